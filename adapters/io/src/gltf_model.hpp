#pragma once
/// \file gltf_model.hpp
/// Private to the io adapter: a glTF 2.0 file (.gltf or .glb) read through tinygltf, with
/// every buffer, view and accessor the scene builder reads checked against its bounds.
/// Faults throw scene_error naming the file and the glTF object ("accessors[3]: ...").

#include <tiny_gltf.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::io::detail {

/// The parsed file. Images keep their encoded bytes (`as_is`): only base-colour textures
/// are decoded, by `base_colour_mean`.
struct gltf_document {
    std::filesystem::path file;
    tinygltf::Model model;

    /// Throws scene_error(file, 0, what).
    [[noreturn]] void fail(const std::string& what) const;
};

/// Reads and parses `file`: a regular file of at most 2 GiB; a .glb's header and chunks
/// checked before tinygltf reads them; the JSON checked for syntax (with its line) and
/// nesting before tinygltf parses it; external buffers and images read only from regular
/// files, with no path expansion.
gltf_document read_gltf(const std::filesystem::path& file);

/// The elements of accessor `index` as (x, y, z), for a FLOAT VEC3 accessor; finite
/// values required when `finite` is set. `user` names what refers to the accessor
/// ("meshes[0].primitives[1].attributes.POSITION") for messages.
std::vector<glm::dvec3> read_vec3_accessor(const gltf_document& doc, int index, const std::string& user, bool finite);
/// The elements of a SCALAR accessor of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT.
std::vector<std::uint32_t> read_index_accessor(const gltf_document& doc, int index, const std::string& user);

/// The mean linear RGB of texture `texture` (sRGB-decoded texels, alpha ignored).
glm::dvec3 base_colour_mean(const gltf_document& doc, int texture, const std::string& user);

}  // namespace bounce::io::detail
