// glTF 2.0 into io::scene: the meshes of every node of the scene with their world
// transforms, base colour and emission as materials, KHR_lights_punctual lights and the
// first perspective camera. docs/gltf.md gives the mappings and units.
#include "gltf_model.hpp"
#include "scene_assembly.hpp"

#include <bounce/io/scene.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

namespace bounce::io::detail {
namespace {

namespace fs = std::filesystem;

// Far above any scene the docs use (Sponza: 66k), and 2 GiB of vertices: a small file
// whose nodes instance a large mesh many times must not exhaust memory.
constexpr std::size_t max_gltf_triangles = std::size_t(1) << 26;

std::string at(const char* array, std::size_t index) { return std::string(array) + "[" + std::to_string(index) + "]"; }

bool finite_all(const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

// A node's own transform: its matrix (column-major) or translation * rotation * scale.
glm::dmat4 local_matrix(const gltf_document& doc, std::size_t index) {
    const tinygltf::Node& n = doc.model.nodes[index];
    const std::string field = at("nodes", index);
    const auto check = [&](const std::vector<double>& v, std::size_t size, const char* key) {
        if (!v.empty() && (v.size() != size || !finite_all(v)))
            doc.fail(field + "." + key + ": expected " + std::to_string(size) + " finite numbers");
    };
    check(n.matrix, 16, "matrix");
    check(n.translation, 3, "translation");
    check(n.rotation, 4, "rotation");
    check(n.scale, 3, "scale");
    if (!n.matrix.empty()) return glm::make_mat4(n.matrix.data());
    glm::dmat4 m(1.0);
    if (!n.translation.empty()) m[3] = glm::dvec4(n.translation[0], n.translation[1], n.translation[2], 1.0);
    if (!n.rotation.empty()) {
        const glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);  // glTF: x y z w
        const double len = glm::length(q);
        if (!(len > 0.0) || !std::isfinite(len)) doc.fail(field + ".rotation: a zero quaternion");
        m = m * glm::mat4_cast(q / len);
    }
    if (!n.scale.empty()) m = m * glm::scale(glm::dmat4(1.0), glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
    return m;
}

struct node_instance {
    std::size_t node;
    glm::dmat4 world;
};

// Every node of the scene to show, parents first, with its world matrix. glTF nodes form
// trees: a node reached twice (two parents, listed twice, a cycle) is a fault.
std::vector<node_instance> scene_nodes(const gltf_document& doc) {
    const auto& m = doc.model;
    std::vector<int> roots;
    if (!m.scenes.empty()) {
        if (m.defaultScene >= int(m.scenes.size()))
            doc.fail("scene: " + std::to_string(m.defaultScene) + " does not exist (the file has " +
                     std::to_string(m.scenes.size()) + " scenes)");
        roots = m.scenes[std::size_t(std::max(m.defaultScene, 0))].nodes;
    } else {  // no scenes: every node that is nobody's child
        std::vector<char> child(m.nodes.size(), 0);
        for (const auto& n : m.nodes)
            for (const int c : n.children)
                if (c >= 0 && std::size_t(c) < m.nodes.size()) child[std::size_t(c)] = 1;
        for (std::size_t i = 0; i < m.nodes.size(); ++i)
            if (!child[i]) roots.push_back(int(i));
    }
    std::vector<node_instance> out;
    std::vector<char> seen(m.nodes.size(), 0);
    std::vector<std::pair<int, glm::dmat4>> stack;
    for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.emplace_back(*r, glm::dmat4(1.0));
    while (!stack.empty()) {
        const auto [index, parent] = stack.back();
        stack.pop_back();
        if (index < 0 || std::size_t(index) >= m.nodes.size())
            doc.fail("node " + std::to_string(index) + " does not exist (the file has " + std::to_string(m.nodes.size()) +
                     "), named in the scene or as a child");
        const auto i = std::size_t(index);
        if (seen[i]) doc.fail(at("nodes", i) + ": reached twice (a child of two nodes, listed twice, or in a cycle)");
        seen[i] = 1;
        out.push_back({i, parent * local_matrix(doc, i)});
        const auto& children = m.nodes[i].children;
        for (auto c = children.rbegin(); c != children.rend(); ++c) stack.emplace_back(*c, out.back().world);
    }
    return out;
}

glm::vec3 factor3(const gltf_document& doc, const std::vector<double>& v, std::size_t size, double top,
                  const std::string& field) {
    if (v.size() != size || !finite_all(v) || std::any_of(v.begin(), v.end(), [&](double x) { return x < 0.0 || x > top; }))
        doc.fail(field + ": expected " + std::to_string(size) + " numbers in [0, " + (top > 1.0 ? "1e30" : "1") + "]");
    return {float(v[0]), float(v[1]), float(v[2])};
}

// Base colour and emission of every material, in the file's order.
void read_materials(const gltf_document& doc, scene& out) {
    for (std::size_t i = 0; i < doc.model.materials.size(); ++i) {
        const tinygltf::Material& mat = doc.model.materials[i];
        const std::string field = at("materials", i);
        const auto& pbr = mat.pbrMetallicRoughness;
        glm::dvec3 albedo(factor3(doc, pbr.baseColorFactor, 4, 1.0, field + ".pbrMetallicRoughness.baseColorFactor"));
        if (pbr.baseColorTexture.index >= 0)
            albedo *= base_colour_mean(doc, pbr.baseColorTexture.index, field + ".pbrMetallicRoughness.baseColorTexture");
        glm::dvec3 emission(factor3(doc, mat.emissiveFactor.empty() ? std::vector<double>(3, 0.0) : mat.emissiveFactor, 3,
                                    double(max_light_value), field + ".emissiveFactor"));
        if (const auto ext = mat.extensions.find("KHR_materials_emissive_strength"); ext != mat.extensions.end()) {
            const tinygltf::Value& strength = ext->second.Get("emissiveStrength");
            const double k = strength.IsNumber() ? strength.GetNumberAsDouble() : -1.0;
            if (!(k >= 0.0 && k <= double(max_light_value)))
                doc.fail(field + ".extensions.KHR_materials_emissive_strength.emissiveStrength: expected a number in [0, 1e30]");
            emission *= k;
        }
        if (mat.emissiveTexture.index >= 0 && emission != glm::dvec3(0.0))
            emission *= base_colour_mean(doc, mat.emissiveTexture.index, field + ".emissiveTexture");
        if (!(emission.x <= double(max_light_value) && emission.y <= double(max_light_value) &&
              emission.z <= double(max_light_value)))
            doc.fail(field + ": emissiveFactor times emissiveStrength beyond 1e30");
        out.materials.push_back({glm::clamp(glm::vec3(albedo), 0.f, 1.f), glm::vec3(emission)});
        out.material_names.push_back(mat.name.empty() ? field : mat.name);
    }
}

// The corners of a primitive's triangles, by mode; false for points and lines (ignored).
bool triangle_corners(const gltf_document& doc, int mode, const std::vector<std::uint32_t>& idx, const std::string& field,
                      std::vector<std::array<std::uint32_t, 3>>& out) {
    out.clear();
    const std::size_t n = idx.size();
    if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) return false;
    if (mode == -1 || mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3 != 0) doc.fail(field + ": " + std::to_string(n) + " indices, not a multiple of 3 (mode TRIANGLES)");
        for (std::size_t i = 0; i + 2 < n; i += 3) out.push_back({idx[i], idx[i + 1], idx[i + 2]});
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {  // the spec's order keeps every triangle's winding
        for (std::size_t i = 0; i + 2 < n; ++i)
            out.push_back({idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]});
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        for (std::size_t i = 0; i + 2 < n; ++i) out.push_back({idx[i + 1], idx[i + 2], idx[0]});
    } else {
        doc.fail(field + ".mode: " + std::to_string(mode) + " (expected 0 to 6)");
    }
    if (out.empty()) doc.fail(field + ": " + std::to_string(n) + " vertices make no triangle");
    return true;
}

struct counts {
    std::size_t degenerate = 0, repaired_normals = 0, points_or_lines = 0, triangles = 0;
};

// One primitive of one node into out: positions to world space, normals by the inverse
// transpose (flat face normals where the primitive has none), winding kept where the
// transform mirrors, zero-area triangles dropped.
class primitive_builder {
public:
    primitive_builder(const gltf_document& doc, scene& out, counts& c) : doc_(doc), out_(out), counts_(c) {}

    void add(const tinygltf::Primitive& prim, const std::string& field, const node_instance& at_node, std::uint32_t material) {
        const auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) doc_.fail(field + ".attributes: no POSITION");
        const std::vector<glm::dvec3> p = read_vec3_accessor(doc_, pos->second, field + ".attributes.POSITION", true);
        std::vector<std::uint32_t> idx;
        if (prim.indices >= 0) {
            idx = read_index_accessor(doc_, prim.indices, field + ".indices");
            for (std::size_t k = 0; k < idx.size(); ++k)
                if (idx[k] >= p.size())
                    doc_.fail(field + ".indices (" + at("accessors", std::size_t(prim.indices)) + "): element " +
                              std::to_string(k) + " is " + std::to_string(idx[k]) + ", past the last of " +
                              std::to_string(p.size()) + " vertices");
        } else {
            idx.resize(p.size());
            for (std::size_t k = 0; k < idx.size(); ++k) idx[k] = std::uint32_t(k);
        }
        if (!triangle_corners(doc_, prim.mode, idx, field, corners_)) {
            ++counts_.points_or_lines;
            return;
        }
        counts_.triangles += corners_.size();
        if (counts_.triangles > max_gltf_triangles)
            doc_.fail("more than " + std::to_string(max_gltf_triangles) + " triangles once the nodes' instances are counted");
        world_.resize(p.size());
        // Without a transform the values pass through bit for bit (1 * -0 + 0 would be +0).
        const bool identity = at_node.world == glm::dmat4(1.0);
        for (std::size_t k = 0; k < p.size(); ++k) {
            world_[k] = identity ? p[k] : glm::dvec3(at_node.world * glm::dvec4(p[k], 1.0));
            if (!(glm::all(glm::lessThanEqual(glm::abs(world_[k]), glm::dvec3(double(max_world_coordinate))))))
                doc_.fail(at("nodes", at_node.node) + ": vertex " + std::to_string(k) + " of " + field +
                          " lies beyond +-1e18 in world space (what float32 rays carry)");
        }
        const auto normal = prim.attributes.find("NORMAL");
        if (normal == prim.attributes.end()) {
            add_flat(at_node, material);
            return;
        }
        const std::vector<glm::dvec3> n = read_vec3_accessor(doc_, normal->second, field + ".attributes.NORMAL", false);
        if (n.size() != p.size())
            doc_.fail(field + ".attributes.NORMAL: " + std::to_string(n.size()) + " normals for " + std::to_string(p.size()) +
                      " positions");
        add_smooth(n, at_node, material);
    }

private:
    // The triangle's corners in world space, in the order that keeps it counter-clockwise
    // seen from its front; false (and counted) when it has no area.
    bool oriented(std::array<std::uint32_t, 3>& c, const node_instance& at_node, glm::dvec3& cross) {
        if (glm::determinant(glm::dmat3(at_node.world)) < 0.0) std::swap(c[1], c[2]);
        const glm::dvec3 p0 = world_[c[0]], p1 = world_[c[1]], p2 = world_[c[2]];
        cross = glm::cross(p1 - p0, p2 - p0);
        if (zero_area(p0, p1, p2)) {
            ++counts_.degenerate;
            return false;
        }
        return true;
    }

    void add_flat(const node_instance& at_node, std::uint32_t material) {
        for (auto c : corners_) {
            glm::dvec3 cross;
            if (!oriented(c, at_node, cross)) continue;
            const glm::vec3 face(cross / glm::length(cross));
            const auto base = std::uint32_t(out_.positions.size());
            for (const std::uint32_t k : c) {
                out_.positions.emplace_back(world_[k]);
                out_.normals.push_back(face);
            }
            out_.triangles.emplace_back(base, base + 1, base + 2);
            out_.material_of.push_back(material);
        }
    }

    void add_smooth(const std::vector<glm::dvec3>& n, const node_instance& at_node, std::uint32_t material) {
        const glm::dmat3 normal_matrix = glm::inverseTranspose(glm::dmat3(at_node.world));
        constexpr auto none = std::numeric_limits<std::uint32_t>::max();
        std::vector<std::uint32_t> vertex_of(n.size(), none);
        // Vertices whose normal is zero or not finite get the area-weighted normal of their
        // faces (the first face's where those cancel), as the OBJ loader does.
        std::vector<glm::dvec3> face_sum, first_face;
        std::vector<std::uint32_t> repair;
        for (auto c : corners_) {
            glm::dvec3 cross;
            if (!oriented(c, at_node, cross)) continue;
            glm::uvec3 tri;
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t v = c[std::size_t(k)];
                if (vertex_of[v] == none) {
                    vertex_of[v] = std::uint32_t(out_.positions.size());
                    out_.positions.emplace_back(world_[v]);
                    const glm::dvec3 w = at_node.world == glm::dmat4(1.0) ? n[v] : normal_matrix * n[v];
                    const double len = glm::length(w);
                    // A unit normal under a rigid transform is kept as it is (no rounding
                    // from a division by 1 +- 1e-7).
                    const bool usable = std::isfinite(len) && len > 0.0;
                    out_.normals.emplace_back(!usable ? glm::dvec3(0.0) : std::abs(len - 1.0) <= 1e-6 ? w : w / len);
                    if (!usable) {
                        if (face_sum.empty()) {
                            face_sum.assign(n.size(), glm::dvec3(0.0));
                            first_face.assign(n.size(), glm::dvec3(0.0));
                        }
                        first_face[v] = cross / glm::length(cross);
                        repair.push_back(v);
                    }
                }
                if (!face_sum.empty()) face_sum[v] += cross;
                tri[k] = vertex_of[v];
            }
            out_.triangles.push_back(tri);
            out_.material_of.push_back(material);
        }
        for (const std::uint32_t v : repair) {
            const double len = glm::length(face_sum[v]);
            out_.normals[vertex_of[v]] = glm::vec3(std::isfinite(len) && len > 0.0 ? face_sum[v] / len : first_face[v]);
        }
        counts_.repaired_normals += repair.size();
    }

    const gltf_document& doc_;
    scene& out_;
    counts& counts_;
    std::vector<glm::dvec3> world_;
    std::vector<std::array<std::uint32_t, 3>> corners_;
};


// KHR_lights_punctual light `index`, placed by its node: at the node's origin, pointing
// along its -z. Intensities are taken as bounce's units: candela as W/sr, lux as W/m^2.
bounce::light read_light(const gltf_document& doc, int index, const node_instance& at_node, std::vector<std::string>& warnings) {
    const auto& lights = doc.model.lights;
    const std::string user = at("nodes", at_node.node) + ".extensions.KHR_lights_punctual.light";
    if (index < 0 || std::size_t(index) >= lights.size())
        doc.fail(user + ": light " + std::to_string(index) + " does not exist (the file has " + std::to_string(lights.size()) + ")");
    const tinygltf::Light& l = lights[std::size_t(index)];
    const std::string field = "extensions.KHR_lights_punctual." + at("lights", std::size_t(index));
    const glm::vec3 colour = factor3(doc, l.color.empty() ? std::vector<double>(3, 1.0) : l.color, 3, 1.0, field + ".color");
    if (!(l.intensity >= 0.0 && l.intensity <= double(max_light_value))) doc.fail(field + ".intensity: expected a number in [0, 1e30]");
    const glm::vec3 value = colour * float(l.intensity);
    const glm::dvec3 position(at_node.world[3]);
    const glm::dvec3 direction = glm::dmat3(at_node.world) * glm::dvec3(0.0, 0.0, -1.0);
    if (!(glm::all(glm::lessThanEqual(glm::abs(position), glm::dvec3(double(max_world_coordinate))))))
        doc.fail(user + ": the light's node lies beyond +-1e18");
    const double length = glm::length(direction);
    if (!(length > 0.0) || !std::isfinite(length)) doc.fail(user + ": the node's transform gives the light no direction");
    if (l.range > 0.0) warnings.push_back(field + ".range ignored: bounce's lights reach everywhere");
    if (l.type == "point") return point_light{glm::vec3(position), value};
    if (l.type == "directional") return directional_light{glm::vec3(direction / length), value};
    if (l.type != "spot") doc.fail(field + ".type: '" + l.type.substr(0, 40) + "' (expected point, spot or directional)");
    const double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
    if (!(inner >= 0.0 && inner < outer && outer <= 0.5 * std::numbers::pi))
        doc.fail(field + ".spot: expected 0 <= innerConeAngle < outerConeAngle <= pi/2");
    // The spec's fade, ((cos a - cos outer) / (cos inner - cos outer))^2 between the cones,
    // as a flat cone of the same power: 2 pi I (1 - cos c) = 2 pi I ((1 - cos inner) +
    // (cos inner - cos outer) / 3).
    const double cos_cone = (2.0 * std::cos(inner) + std::cos(outer)) / 3.0;
    spot_light spot;
    spot.position = glm::vec3(position);
    spot.direction = glm::vec3(direction / length);
    spot.intensity = value;
    spot.cone_deg = float(std::acos(cos_cone) * 180.0 / std::numbers::pi);
    spot.falloff = spot_light::falloff_kind::none;
    return spot;
}

// A perspective camera at its node: looking along -z, up +y; false for orthographic ones.
bool read_camera(const gltf_document& doc, const node_instance& at_node, bounce::camera& out, std::vector<std::string>& warnings) {
    const int index = doc.model.nodes[at_node.node].camera;
    const std::string user = at("nodes", at_node.node) + ".camera";
    if (std::size_t(index) >= doc.model.cameras.size())
        doc.fail(user + ": camera " + std::to_string(index) + " does not exist (the file has " +
                 std::to_string(doc.model.cameras.size()) + ")");
    const tinygltf::Camera& c = doc.model.cameras[std::size_t(index)];
    const std::string field = at("cameras", std::size_t(index));
    if (c.type != "perspective") {
        warnings.push_back(field + ": type " + c.type.substr(0, 20) + ", skipped (bounce's camera is a perspective pinhole)");
        return false;
    }
    const double fov = c.perspective.yfov * 180.0 / std::numbers::pi;
    if (!(fov > 0.0 && fov < 180.0)) doc.fail(field + ".perspective.yfov: expected a number in (0, pi)");
    const glm::dmat3 r(at_node.world);
    const glm::dvec3 position(at_node.world[3]), forward = glm::normalize(r * glm::dvec3(0.0, 0.0, -1.0));
    out.position = glm::vec3(position);
    out.look_at = glm::vec3(position + std::max(1.0, glm::length(position)) * forward);
    out.up = glm::vec3(r * glm::dvec3(0.0, 1.0, 0.0));
    out.fov_y_deg = float(fov);
    try {
        if (!(glm::all(glm::lessThanEqual(glm::abs(position), glm::dvec3(double(max_world_coordinate))))))
            throw parameter_error("position", "beyond +-1e18");
        out.validate();
    } catch (const parameter_error& e) {
        doc.fail(user + ": the node's transform gives no usable camera (" + e.what() + ")");
    }
    return true;
}

}  // namespace

gltf_extras load_gltf_mesh(const fs::path& file, const bounce::material& default_material, scene& out) {
    const gltf_document doc = read_gltf(file);
    out.positions.clear();
    out.normals.clear();
    out.triangles.clear();
    out.material_of.clear();
    out.materials.clear();
    out.material_names.clear();
    read_materials(doc, out);
    std::uint32_t default_index = std::numeric_limits<std::uint32_t>::max();
    counts c;
    primitive_builder builder(doc, out, c);
    gltf_extras extras;
    std::size_t skinned = 0;
    for (const node_instance& inst : scene_nodes(doc)) {
        const tinygltf::Node& node = doc.model.nodes[inst.node];
        if (node.camera >= 0 && !extras.camera) {
            bounce::camera cam;
            if (read_camera(doc, inst, cam, out.warnings)) extras.camera = cam;
        }
        if (const auto ext = node.extensions.find("KHR_lights_punctual"); ext != node.extensions.end()) {
            const tinygltf::Value& light = ext->second.Get("light");
            extras.lights.push_back(read_light(doc, light.IsInt() ? light.Get<int>() : -1, inst, out.warnings));
        }
        if (node.mesh < 0) continue;
        if (std::size_t(node.mesh) >= doc.model.meshes.size())
            doc.fail(at("nodes", inst.node) + ".mesh: mesh " + std::to_string(node.mesh) + " does not exist (the file has " +
                     std::to_string(doc.model.meshes.size()) + ")");
        skinned += node.skin >= 0 ? 1 : 0;
        const tinygltf::Mesh& mesh = doc.model.meshes[std::size_t(node.mesh)];
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = mesh.primitives[p];
            const std::string field = at("meshes", std::size_t(node.mesh)) + "." + at("primitives", p);
            std::uint32_t material = std::uint32_t(prim.material);
            if (prim.material >= int(doc.model.materials.size()))
                doc.fail(field + ".material: material " + std::to_string(prim.material) + " does not exist (the file has " +
                         std::to_string(doc.model.materials.size()) + ")");
            if (prim.material < 0) {
                if (default_index == std::numeric_limits<std::uint32_t>::max()) {
                    default_index = std::uint32_t(out.materials.size());
                    out.materials.push_back(default_material);
                    out.material_names.push_back("default");
                }
                material = default_index;
            }
            builder.add(prim, field, inst, material);
        }
    }
    if (out.triangles.empty())
        doc.fail(c.triangles == 0 ? "no triangles: the scene's nodes hold no triangle mesh"
                                  : "no triangles: every triangle is degenerate (zero area)");
    if (c.degenerate) out.warnings.push_back("dropped " + std::to_string(c.degenerate) + " degenerate (zero-area) triangle(s)");
    if (c.repaired_normals)
        out.warnings.push_back(std::to_string(c.repaired_normals) +
                               " vertex normal(s) zero or not finite: replaced by the area-weighted normal of their faces");
    if (c.points_or_lines) out.warnings.push_back("ignored " + std::to_string(c.points_or_lines) + " point/line primitive(s)");
    if (skinned) out.warnings.push_back(std::to_string(skinned) + " skinned node(s) shown in their bind pose (skins ignored)");
    return extras;
}

}  // namespace bounce::io::detail

namespace bounce::io {

scene load_gltf(const std::filesystem::path& file, const bounce::material& default_material) {
    scene s;
    s.name = file.stem().string();
    s.source = file;
    detail::gltf_extras extras = detail::load_gltf_mesh(file, default_material, s);
    s.lights = std::move(extras.lights);
    s.use_emission = true;
    s.use_emission = !s.emissive_triangles().empty();
    detail::place_camera_and_light(file, s, extras.camera);
    return s;
}

}  // namespace bounce::io
