#pragma once
/// \file scene_view.hpp
/// `scene_view`: a non-owning view of a renderer's triangle mesh, materials and lights, the
/// one scene type every adapter takes. A renderer points its spans at its own arrays (they
/// must outlive the view and every object built from it); `io::scene` hands one out for
/// the scenes bounce loads from files.

#include <bounce/errors.hpp>
#include <bounce/light.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace bounce {

/// A diffuse (Lambertian) material.
struct material {
    glm::vec3 albedo{0.8f};    ///< diffuse reflectance rho_d per channel, in [0, 1] (MTL Kd)
    glm::vec3 emission{0.f};   ///< emitted radiance, W/(m^2 sr) per channel (MTL Ke); see use_emission
};

/// Triangles, their materials and the scene's lights, as spans over the caller's memory.
struct scene_view {
    std::span<const glm::vec3> positions;       ///< vertex positions, world space (metres by convention)
    std::span<const glm::vec3> normals;         ///< unit vertex shading normals, one per position; empty: face normals
    std::span<const glm::uvec3> triangles;      ///< indices into positions (and normals), counter-clockwise = front
    std::span<const std::uint32_t> material_of; ///< material index of each triangle
    std::span<const material> materials;
    std::span<const light> lights;
    bool use_emission = false;  ///< triangles whose material has emission > 0 are area lights too

    /// Throws parameter_error naming the span at fault ("scene.positions", "scene.triangles"
    /// ...) unless the mesh is consistent and finite: positions within max_world_coordinate
    /// (light.hpp), finite normals, normals
    /// empty or one per position, indices in range, one material index per triangle and each
    /// in range, albedo and emission finite and non-negative (emission at most max_light_value), and fewer than 2^32 - 1
    /// vertices and triangles (32-bit indices on every backend). Degenerate (zero-area)
    /// triangles are allowed: backends give them no hits and no light.
    void validate_mesh() const {
        using detail::finite3;
        const std::size_t nv = positions.size(), nt = triangles.size();
        for (std::size_t i = 0; i < nv; ++i)
            if (!detail::bounded3(positions[i], max_world_coordinate))
                throw parameter_error("scene.positions", "vertex " + std::to_string(i) +
                                                             (finite3(positions[i]) ? " has a coordinate beyond +-1e18 "
                                                                                      "(what float32 rays carry)"
                                                                                    : " is not finite"));
        if (!normals.empty() && normals.size() != nv)
            throw parameter_error("scene.normals", "has " + std::to_string(normals.size()) + " entries for " +
                                                       std::to_string(nv) + " positions");
        for (std::size_t i = 0; i < normals.size(); ++i)
            if (!finite3(normals[i]))
                throw parameter_error("scene.normals", "normal " + std::to_string(i) + " is not finite");
        constexpr std::size_t limit = std::numeric_limits<std::uint32_t>::max();
        if (nt >= limit || nv >= limit)
            throw parameter_error("scene.triangles", "more than 2^32 - 2 triangles or vertices");
        for (std::size_t t = 0; t < nt; ++t)
            for (int k = 0; k < 3; ++k)
                if (triangles[t][k] >= nv)
                    throw parameter_error("scene.triangles", "triangle " + std::to_string(t) + " refers to vertex " +
                                                                 std::to_string(triangles[t][k]) + " of " +
                                                                 std::to_string(nv));
        if (material_of.size() != nt)
            throw parameter_error("scene.material_of", "has " + std::to_string(material_of.size()) +
                                                           " entries for " + std::to_string(nt) + " triangles");
        for (std::size_t t = 0; t < nt; ++t)
            if (material_of[t] >= materials.size())
                throw parameter_error("scene.material_of", "triangle " + std::to_string(t) + " uses material " +
                                                               std::to_string(material_of[t]) + " of " +
                                                               std::to_string(materials.size()));
        for (std::size_t m = 0; m < materials.size(); ++m) {
            if (!detail::non_negative3(materials[m].albedo))
                throw parameter_error("scene.materials", "material " + std::to_string(m) +
                                                             " has a negative or non-finite albedo");
            if (!detail::light_value3(materials[m].emission))
                throw parameter_error("scene.materials", "material " + std::to_string(m) +
                                                             " has a negative, non-finite or above-1e30 emission");
        }
    }

    /// validate_mesh(), then the lights as validate_lights asks ("scene.lights[i]").
    void validate() const {
        validate_mesh();
        validate_lights(lights);
    }

    /// Whether triangle `t` is an area light: use_emission and its material emits in some channel.
    bool emits(std::size_t t) const noexcept {
        if (!use_emission || t >= material_of.size() || material_of[t] >= materials.size()) return false;
        const glm::vec3 e = materials[material_of[t]].emission;
        return e.r > 0.f || e.g > 0.f || e.b > 0.f;
    }

    /// Indices of the triangles that emit (empty unless use_emission).
    std::vector<std::uint32_t> emissive_triangles() const {
        std::vector<std::uint32_t> out;
        for (std::size_t t = 0; t < triangles.size(); ++t)
            if (emits(t)) out.push_back(std::uint32_t(t));
        return out;
    }

    /// Axis-aligned bounds of all vertices, {min, max}; {0, 0} for an empty mesh.
    std::pair<glm::vec3, glm::vec3> bounds() const noexcept {
        if (positions.empty()) return {glm::vec3(0.f), glm::vec3(0.f)};
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        for (const auto& p : positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        return {lo, hi};
    }
};

}  // namespace bounce
