// OBJ+MTL into io::scene through tinyobjloader.
//
// tinyobjloader parses; it also accepts some garbage without a word (a face index past the
// last vertex, "v 1 abc 3" read as (1, 0, 3), a truncated "v 1 2", an unknown material),
// and reports a few faults without the line. So before handing the text to it, one pass
// over the lines checks what it would let through, names the line, and reads nothing
// into the mesh: the mesh is built from tinyobjloader's data only.
#include "scene_assembly.hpp"

#include "text_lines.hpp"

#include <bounce/io/scene.hpp>

#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace bounce::io::detail {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t max_obj_bytes = std::size_t(2) << 30;  // 2 GiB: far beyond any mesh the docs use (7.6 MB)
constexpr std::size_t max_mtl_bytes = std::size_t(64) << 20;
// tinyobjloader's ear clipping costs up to O(n^3) for an n-gon; 256 keeps the worst face
// below a millisecond and is far above what modelling tools write.
constexpr std::size_t max_face_vertices = 256;

// 'text', cut at 80 characters. (append, not "'" + std::string: GCC 12 bug 105651 warns.)
std::string in_quotes(std::string_view s) {
    std::string out(1, '\'');
    out.append(s.substr(0, 80)).push_back('\'');
    return out;
}

// The largest positive index of one kind seen in faces, and the first line using it.
struct index_use {
    long long index = 0;
    std::size_t line = 0;
};

// What the line check learns about an OBJ besides its faults.
struct obj_survey {
    std::size_t positions = 0, normals = 0, texcoords = 0, faces = 0, lines_or_points = 0;
    index_use max_position, max_normal, max_texcoord;
    std::vector<std::pair<std::string, std::size_t>> usemtl;  // name, first line naming it
    std::vector<std::pair<std::string, std::size_t>> mtllib;  // text after the keyword, line
};

bool all_numbers(const std::vector<std::string_view>& tokens, std::size_t first, std::size_t count) {
    if (tokens.size() < first + count) return false;
    for (std::size_t i = first; i < first + count; ++i)
        if (!parse_float(tokens[i])) return false;
    return true;
}

// Nothing after the numbers but an end-of-line comment.
bool rest_is_comment(const std::vector<std::string_view>& tokens, std::size_t from) {
    return tokens.size() <= from || tokens[from].front() == '#';
}

// One index of a face vertex: 1-based, or negative relative to the `count` seen so far.
void check_index(const fs::path& file, std::size_t line, std::string_view what, std::string_view token,
                 std::size_t count, index_use& max_use) {
    const auto value = parse_integer(token);
    if (!value) throw scene_error(file, line, "f: " + std::string(what) + " index " + in_quotes(token) + " is not an integer");
    if (*value == 0) throw scene_error(file, line, "f: " + std::string(what) + " index 0 (OBJ indices start at 1)");
    // tinyobjloader reads indices with atoi: beyond int they would wrap.
    if (*value > std::numeric_limits<int>::max() || *value < -static_cast<long long>(std::numeric_limits<int>::max()))
        throw scene_error(file, line, "f: " + std::string(what) + " index " + in_quotes(token) + " out of range");
    if (*value < 0) {
        if (static_cast<long long>(count) + *value < 0)
            throw scene_error(file, line,
                              "f: relative " + std::string(what) + " index " + std::to_string(*value) +
                                  " reaches before the first one (" + std::to_string(count) + " so far)");
    } else if (*value > max_use.index) {
        max_use = {*value, line};
    }
}

// "v", "v/vt", "v//vn" or "v/vt/vn".
void check_face_vertex(const fs::path& file, std::size_t line, std::string_view token, obj_survey& s) {
    std::array<std::string_view, 3> part{};
    std::size_t n = 0, start = 0;
    for (std::size_t i = 0; i <= token.size(); ++i) {
        if (i == token.size() || token[i] == '/') {
            if (n == 3)
                throw scene_error(file, line, "f: vertex " + in_quotes(token) + ": expected v, v/vt, v//vn or v/vt/vn");
            part[n++] = token.substr(start, i - start);
            start = i + 1;
        }
    }
    check_index(file, line, "vertex", part[0], s.positions, s.max_position);
    if (n >= 2 && !(n == 3 && part[1].empty())) check_index(file, line, "texcoord", part[1], s.texcoords, s.max_texcoord);
    if (n == 3) check_index(file, line, "normal", part[2], s.normals, s.max_normal);
}

void check_max_index(const fs::path& file, const index_use& use, std::size_t count, std::string_view what) {
    if (use.index > static_cast<long long>(count))
        throw scene_error(file, use.line,
                          "f: refers to " + std::string(what) + " " + std::to_string(use.index) + " but the file has " +
                              std::to_string(count));
}

obj_survey survey_obj(const fs::path& file, std::string_view text) {
    obj_survey s;
    line_reader lines(text);
    std::string_view line;
    std::vector<std::string_view> tok;
    while (lines.next(line)) {
        const std::size_t ln = lines.number();
        if (line.find('\0') != std::string_view::npos) throw scene_error(file, ln, "NUL byte: not a text file");
        split_tokens(line, tok);
        if (tok.empty() || tok[0].front() == '#') continue;
        const std::string_view kw = tok[0];
        if (kw == "v") {
            // Three coordinates; a fourth (w) or three more (vertex colour) may follow.
            if (!all_numbers(tok, 1, 3)) throw scene_error(file, ln, "v: expected 3 finite numbers (x y z)");
            for (std::size_t i = 1; i < 4; ++i)
                if (std::abs(*parse_float(tok[i])) > max_world_coordinate)
                    throw scene_error(file, ln, "v: coordinate " + std::string(tok[i]) +
                                                    " beyond +-1e18, what float32 rays carry (scale the mesh)");
            ++s.positions;
        } else if (kw == "vn") {
            // Zero or overflowing normals are repaired later (face normal), not refused.
            if (tok.size() < 4) throw scene_error(file, ln, "vn: expected 3 numbers (x y z)");
            for (std::size_t i = 1; i < 4; ++i)
                if (!is_number(tok[i])) throw scene_error(file, ln, "vn: expected 3 numbers (x y z)");
            if (!rest_is_comment(tok, 4)) throw scene_error(file, ln, "vn: expected 3 numbers (x y z)");
            ++s.normals;
        } else if (kw == "vt") {
            if (tok.size() < 2) throw scene_error(file, ln, "vt: expected 1 to 3 numbers (u [v [w]])");
            for (std::size_t i = 1; i < tok.size() && i < 4 && tok[i].front() != '#'; ++i)
                if (!parse_float(tok[i])) throw scene_error(file, ln, "vt: expected 1 to 3 numbers (u [v [w]])");
            ++s.texcoords;
        } else if (kw == "f") {
            const std::size_t n = tok.size() - 1;
            if (n < 3) throw scene_error(file, ln, "f: a face needs at least 3 vertices, this one has " + std::to_string(n));
            if (n > max_face_vertices)
                throw scene_error(file, ln,
                                  "f: " + std::to_string(n) + " vertices; at most " + std::to_string(max_face_vertices) +
                                      " per face are supported");
            for (std::size_t i = 1; i < tok.size(); ++i) check_face_vertex(file, ln, tok[i], s);
            ++s.faces;
        } else if (kw == "usemtl") {
            if (tok.size() < 2) throw scene_error(file, ln, "usemtl: expected a material name");
            const std::string name(tok[1]);
            if (std::none_of(s.usemtl.begin(), s.usemtl.end(), [&](const auto& u) { return u.first == name; }))
                s.usemtl.emplace_back(name, ln);
        } else if (kw == "mtllib") {
            if (tok.size() < 2) throw scene_error(file, ln, "mtllib: expected a file name");
            s.mtllib.emplace_back(std::string(line.substr(line.find("mtllib") + 6)), ln);
        } else if (kw == "l" || kw == "p") {
            ++s.lines_or_points;
        }
    }
    if (s.faces == 0) throw scene_error(file, 0, "no faces: the mesh is empty");
    check_max_index(file, s.max_position, s.positions, "vertex");
    check_max_index(file, s.max_normal, s.normals, "normal");
    check_max_index(file, s.max_texcoord, s.texcoords, "texcoord");
    return s;
}

// Checks the MTL lines tinyobjloader would read wrongly without a word, then lets it parse.
void check_mtl(const fs::path& file, std::string_view text) {
    line_reader lines(text);
    std::string_view line;
    std::vector<std::string_view> tok;
    std::size_t materials = 0;
    while (lines.next(line)) {
        const std::size_t ln = lines.number();
        if (line.find('\0') != std::string_view::npos) throw scene_error(file, ln, "NUL byte: not a text file");
        split_tokens(line, tok);
        if (tok.empty() || tok[0].front() == '#') continue;
        if (tok[0] == "newmtl") {
            if (tok.size() < 2) throw scene_error(file, ln, "newmtl: expected a material name");
            ++materials;
        } else if (tok[0] == "Kd" || tok[0] == "Ke") {
            const bool kd = tok[0] == "Kd";
            const std::string what = kd ? "Kd: expected 3 numbers in [0, 1] (diffuse reflectance r g b)"
                                        : "Ke: expected 3 finite numbers >= 0 (emitted radiance r g b)";
            if (!all_numbers(tok, 1, 3) || !rest_is_comment(tok, 4)) throw scene_error(file, ln, what);
            for (std::size_t i = 1; i < 4; ++i) {
                const float c = *parse_float(tok[i]);
                if (c < 0.f || (kd && c > 1.f)) throw scene_error(file, ln, what);
            }
        }
    }
    if (materials == 0) throw scene_error(file, 0, "no material (newmtl) in the file");
}

// tinyobjloader asks this for each `mtllib` file: it resolves the name beside the OBJ,
// refuses what is not a regular file, checks the lines, then lets tinyobjloader parse.
class checked_mtl_reader final : public tinyobj::MaterialReader {
public:
    checked_mtl_reader(fs::path obj, const obj_survey& survey) : obj_(std::move(obj)), survey_(survey) {}

    bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                    std::map<std::string, int>* map, std::string* warn, std::string* /*err: faults throw*/) override {
        const fs::path mtl = obj_.parent_path() / name;
        std::error_code ec;
        if (!fs::exists(mtl, ec)) {
            std::size_t line = 0;
            for (const auto& [text, ln] : survey_.mtllib)
                if (text.find(name) != std::string::npos) {
                    line = ln;
                    break;
                }
            throw scene_error(mtl, 0,
                              "no such file (named by mtllib on line " + std::to_string(line) + " of " +
                                  obj_.filename().string() + ")");
        }
        const std::string text = read_text_file(mtl, max_mtl_bytes);
        check_mtl(mtl, text);
        std::istringstream in(text);
        std::string w, e;
        tinyobj::LoadMtl(map, materials, &in, &w, &e);
        if (warn) *warn += w;
        if (!e.empty()) throw scene_error(mtl, 0, "tinyobjloader: " + e.substr(0, e.find('\n')));
        return true;
    }

private:
    fs::path obj_;
    const obj_survey& survey_;
};

std::string plural(std::size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

// What tinyobjloader read from an OBJ and its MTL files.
struct obj_data {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warnings;
};

obj_data parse_obj(const fs::path& file, const std::string& text, const obj_survey& survey) {
    obj_data d;
    std::string err;
    checked_mtl_reader mtl_reader(file, survey);
    std::istringstream in(text);
    const bool ok = tinyobj::LoadObj(&d.attrib, &d.shapes, &d.materials, &d.warnings, &err, &in, &mtl_reader,
                                     /*triangulate=*/true, /*default_vcols_fallback=*/false);
    if (!ok || !err.empty()) {
        const std::string first = err.substr(0, err.find('\n'));
        throw scene_error(file, line_in_message(err), "tinyobjloader: " + (first.empty() ? "failed" : first));
    }
    return d;
}

// tinyobjloader's warnings into out.warnings, but a `usemtl` naming no material of the
// mtllib files is a fault (a truncated or wrong MTL); without any mtllib it only means
// "default material".
void take_warnings(const fs::path& file, const std::string& warnings, const obj_survey& survey, scene& out) {
    std::istringstream warn_lines(warnings);
    std::string w;
    // tinyobjloader: "material [ 'NAME' ] not found in .mtl"
    constexpr std::string_view not_found_head = "material [ '", not_found_tail = "' ] not found";
    while (std::getline(warn_lines, w)) {
        if (w.empty()) continue;
        const std::size_t head = w.find(not_found_head), tail = w.rfind(not_found_tail);
        if (head != std::string::npos && tail != std::string::npos && tail >= head + not_found_head.size()) {
            const std::string name = w.substr(head + not_found_head.size(), tail - head - not_found_head.size());
            std::size_t line = 0;
            for (const auto& [n, ln] : survey.usemtl)
                if (n == name) line = ln;
            if (survey.mtllib.empty())
                out.warnings.push_back("usemtl " + in_quotes(name) + " without mtllib: default material used");
            else
                throw scene_error(file, line,
                                  "usemtl " + in_quotes(name) +
                                      ": no such material in the mtllib files, or named before its mtllib");
        } else if (w != ".") {
            out.warnings.push_back("tinyobjloader: " + w);
        }
    }
}

// Builds out's vertices, triangles and materials from tinyobjloader's faces: one vertex
// per (position index, normal index) pair; degenerate triangles dropped; vertices without
// a usable normal get the area-weighted normal of their faces.
class mesh_assembly {
public:
    mesh_assembly(const fs::path& file, const obj_data& d, const bounce::material& default_material, scene& out)
        : file_(file), attrib_(d.attrib), default_material_(default_material), out_(out),
          npos_(d.attrib.vertices.size() / 3), nnorm_(d.attrib.normals.size() / 3) {
        out.materials.clear();
        out.material_names.clear();
        for (const auto& tm : d.materials) {
            out.materials.push_back({{tm.diffuse[0], tm.diffuse[1], tm.diffuse[2]},
                                     {tm.emission[0], tm.emission[1], tm.emission[2]}});
            out.material_names.push_back(tm.name);
        }
        out.positions.clear();
        out.normals.clear();
        out.triangles.clear();
        out.material_of.clear();
    }

    void add_shape(const tinyobj::mesh_t& mesh) {
        std::size_t offset = 0;
        for (std::size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
            const std::size_t fv = mesh.num_face_vertices[f];
            const std::size_t first = offset;
            offset += fv;
            if (fv != 3 || offset > mesh.indices.size()) continue;  // tinyobjloader triangulated already
            const int mid = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
            add_triangle({mesh.indices[first], mesh.indices[first + 1], mesh.indices[first + 2]}, mid);
        }
    }

    // Smooth normals where none was given, then the warnings of what was repaired.
    void finish() {
        for (std::size_t v = 0; v < out_.positions.size(); ++v) {
            if (!smooth_[v]) continue;
            const double len = glm::length(area_normal_[v]);
            // Opposite faces can cancel; the first face's normal is then the honest choice.
            out_.normals[v] = std::isfinite(len) && len > 0.0 ? glm::vec3(area_normal_[v] / len) : glm::vec3(first_face_[v]);
        }
        if (out_.triangles.empty())
            throw scene_error(file_, 0, "no triangles: every face is degenerate (zero area)");
        if (degenerate_)
            out_.warnings.push_back("dropped " + plural(degenerate_, "degenerate (zero-area) triangle",
                                                        "degenerate (zero-area) triangles"));
        if (repaired_normals_)
            out_.warnings.push_back(plural(repaired_normals_, "vertex normal", "vertex normals") +
                                    " zero or not finite: replaced by the area-weighted normal of their faces");
        if (repeated_)
            out_.warnings.push_back(plural(repeated_, "triangle repeats", "triangles repeat") + " an earlier one (kept)");
    }

private:
    struct triple_hash {
        std::size_t operator()(const std::array<int, 3>& t) const noexcept {
            std::uint64_t h = 1469598103934665603ull;
            for (int v : t) h = (h ^ std::uint32_t(v)) * 1099511628211ull;
            return std::size_t(h);
        }
    };

    glm::dvec3 position(int i) const {
        return glm::dvec3(attrib_.vertices[3 * std::size_t(i)], attrib_.vertices[3 * std::size_t(i) + 1],
                          attrib_.vertices[3 * std::size_t(i) + 2]);
    }

    void add_triangle(const std::array<tinyobj::index_t, 3>& c, int material_id) {
        for (const auto& k : c)
            if (k.vertex_index < 0 || std::size_t(k.vertex_index) >= npos_ || k.normal_index >= int(nnorm_))
                throw scene_error(file_, 0, "tinyobjloader returned an index out of range");
        const glm::dvec3 p0 = position(c[0].vertex_index), p1 = position(c[1].vertex_index),
                         p2 = position(c[2].vertex_index);
        const glm::dvec3 cross = glm::cross(p1 - p0, p2 - p0);
        const double area2 = glm::length(cross);
        if (zero_area(p0, p1, p2)) {
            ++degenerate_;
            return;
        }
        std::array<int, 3> key3{c[0].vertex_index, c[1].vertex_index, c[2].vertex_index};
        std::sort(key3.begin(), key3.end());
        if (!seen_.insert(key3).second) ++repeated_;
        glm::uvec3 tri;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = vertex(c[std::size_t(k)], cross / area2);
            // Area-weighted average: |e1 x e2| is twice the area.
            if (smooth_[v]) area_normal_[v] += cross;
            tri[k] = v;
        }
        out_.triangles.push_back(tri);
        out_.material_of.push_back(material_index(material_id));
    }

    // The output vertex of corner c, added on first use (face_normal: the unit normal of
    // the face that adds it).
    std::uint32_t vertex(const tinyobj::index_t& c, const glm::dvec3& face_normal) {
        const std::uint64_t key = (std::uint64_t(std::uint32_t(c.vertex_index)) << 32) | std::uint32_t(c.normal_index + 1);
        auto [it, inserted] = vertex_of_.try_emplace(key, std::uint32_t(out_.positions.size()));
        if (!inserted) return it->second;
        out_.positions.emplace_back(position(c.vertex_index));
        first_face_.push_back(face_normal);
        area_normal_.emplace_back(0.0);
        glm::dvec3 n(0.0);
        if (c.normal_index >= 0) {
            const std::size_t j = 3 * std::size_t(c.normal_index);
            n = {attrib_.normals[j], attrib_.normals[j + 1], attrib_.normals[j + 2]};
        }
        const double len = glm::length(n);
        const bool usable = std::isfinite(len) && len > 0.0;
        if (c.normal_index >= 0 && !usable) ++repaired_normals_;
        smooth_.push_back(usable ? 0 : 1);
        out_.normals.emplace_back(usable ? n / len : glm::dvec3(0.0));
        return it->second;
    }

    // The material of a face: its MTL material, else the default material, appended on first use.
    std::uint32_t material_index(int material_id) {
        if (material_id >= 0 && std::size_t(material_id) < out_.materials.size()) return std::uint32_t(material_id);
        if (default_index_ == std::numeric_limits<std::uint32_t>::max()) {
            default_index_ = std::uint32_t(out_.materials.size());
            out_.materials.push_back(default_material_);
            out_.material_names.push_back("default");
        }
        return default_index_;
    }

    const fs::path& file_;
    const tinyobj::attrib_t& attrib_;
    const bounce::material& default_material_;
    scene& out_;
    std::size_t npos_, nnorm_;
    std::uint32_t default_index_ = std::numeric_limits<std::uint32_t>::max();
    std::unordered_map<std::uint64_t, std::uint32_t> vertex_of_;
    std::vector<glm::dvec3> area_normal_;  // sum of face cross products, for vertices to smooth
    std::vector<glm::dvec3> first_face_;   // unit normal of the first face using the vertex
    std::vector<char> smooth_;             // 1 where no usable vn was given
    std::unordered_set<std::array<int, 3>, triple_hash> seen_;
    std::size_t degenerate_ = 0, repaired_normals_ = 0, repeated_ = 0;
};

}  // namespace

void load_obj_mesh(const fs::path& file, const bounce::material& default_material, scene& out) {
    const std::string text = read_text_file(file, max_obj_bytes);
    const obj_survey survey = survey_obj(file, text);
    const obj_data d = parse_obj(file, text, survey);
    take_warnings(file, d.warnings, survey, out);
    mesh_assembly mesh(file, d, default_material, out);
    for (const auto& shape : d.shapes) mesh.add_shape(shape.mesh);
    mesh.finish();
    if (survey.lines_or_points)
        out.warnings.push_back("ignored " + plural(survey.lines_or_points, "line/point element", "line/point elements"));
}

}  // namespace bounce::io::detail
