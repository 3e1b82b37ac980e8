// glTF 2.0 files through tinygltf, and the checked reading of their accessors.
//
// tinygltf parses; it checks the JSON's types but not every index or byte range it hands
// over, and a .glb's chunk lengths are trusted. So the .glb container and the JSON's
// syntax and nesting are checked before tinygltf sees them, tinygltf reads external files
// through callbacks that refuse what is not a regular file (and expand no paths), and
// every accessor is checked against its view and buffer before a byte of it is read.
#include "gltf_model.hpp"

#include "scene_assembly.hpp"
#include "text_lines.hpp"

#include <bounce/io/scene.hpp>

#include <algorithm>
#include <array>
#include <initializer_list>
#include <climits>
#include <cmath>
#include <cstring>
#include <optional>

namespace bounce::io::detail {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t max_gltf_bytes = std::size_t(2) << 30;  // as an OBJ; tinygltf takes an unsigned int length
constexpr int max_gltf_json_depth = 64;                        // the format nests 7 deep; extras may nest more

std::string at(const char* array, int index) { return std::string(array) + "[" + std::to_string(index) + "]"; }

std::uint32_t le32(const std::string& bytes, std::size_t offset) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | std::uint8_t(bytes[offset + std::size_t(i)]);
    return v;
}

// The JSON chunk of a .glb, after checking the 12-byte header and the chunk lengths.
std::string glb_json_chunk(const fs::path& file, const std::string& bytes) {
    if (bytes.size() < 20) throw scene_error(file, 0, "GLB: " + std::to_string(bytes.size()) + " bytes, shorter than a header and one chunk (20)");
    if (bytes.compare(0, 4, "glTF") != 0) throw scene_error(file, 0, "GLB: the file does not start with the magic 'glTF'");
    if (le32(bytes, 4) != 2) throw scene_error(file, 0, "GLB: container version " + std::to_string(le32(bytes, 4)) + " (expected 2)");
    const std::size_t length = le32(bytes, 8);
    if (length != bytes.size())
        throw scene_error(file, 0, "GLB: the header gives " + std::to_string(length) + " bytes, the file has " +
                                       std::to_string(bytes.size()) + " (truncated?)");
    const std::size_t json_length = le32(bytes, 12);
    if (le32(bytes, 16) != 0x4E4F534Au) throw scene_error(file, 0, "GLB: the first chunk is not JSON");
    if (json_length == 0 || json_length > length - 20)
        throw scene_error(file, 0, "GLB: the JSON chunk's length " + std::to_string(json_length) + " does not fit the file");
    const std::size_t next = 20 + json_length;
    if (next < length) {
        if (length - next < 8) throw scene_error(file, 0, "GLB: " + std::to_string(length - next) + " stray bytes after the JSON chunk");
        const std::size_t bin_length = le32(bytes, next);
        if (bin_length > length - next - 8)
            throw scene_error(file, 0, "GLB: the second chunk's length " + std::to_string(bin_length) + " does not fit the file");
    }
    return bytes.substr(20, json_length);
}

// tinygltf's file callbacks: external buffers and images are read as the OBJ loader reads
// files (regular files only, bounded size); the first fault is kept to be thrown as is.
struct file_access {
    std::optional<scene_error> fault;
};

bool any_path_exists(const std::string&, void*) { return true; }  // ReadWholeFile says what is wrong
std::string no_expansion(const std::string& path, void*) { return path; }
bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    try {
        const std::string bytes = read_text_file(path, max_gltf_bytes);
        out->assign(bytes.begin(), bytes.end());
        return true;
    } catch (const scene_error& e) {
        auto& access = *static_cast<file_access*>(user);
        if (!access.fault) access.fault = e;
        if (err) *err += e.what();
        return false;
    }
}
bool write_nothing(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "bounce does not write glTF files";
    return false;
}

// Keeps an image's encoded bytes; base_colour_mean decodes the few that are needed.
bool keep_encoded(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                  int size, void*) {
    image->image.assign(bytes, bytes + size);
    image->as_is = true;
    return true;
}

// tinygltf's message, first line, without its trailing newline.
std::string first_line(const std::string& s) {
    const std::string line = s.substr(0, s.find('\n'));
    return line.empty() ? "failed" : line.substr(0, 300);
}

}  // namespace

void gltf_document::fail(const std::string& what) const { throw scene_error(file, 0, what); }

gltf_document read_gltf(const fs::path& file) {
    gltf_document doc;
    doc.file = file;
    const std::string bytes = read_text_file(file, max_gltf_bytes);
    const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
    if (!binary && file.extension() == ".glb") glb_json_chunk(file, bytes);  // names what is wrong with the header
    check_json_text(file, binary ? glb_json_chunk(file, bytes) : bytes, max_gltf_json_depth);

    file_access access;
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks({&any_path_exists, &no_expansion, &read_whole_file, &write_nothing, &access});
    loader.SetImageLoader(&keep_encoded, nullptr);
    std::string err, warn;
    const std::string base = file.parent_path().empty() ? std::string(".") : file.parent_path().string();
    const bool ok = binary ? loader.LoadBinaryFromMemory(&doc.model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                         static_cast<unsigned int>(bytes.size()), base)
                           : loader.LoadASCIIFromString(&doc.model, &err, &warn, bytes.data(),
                                                        static_cast<unsigned int>(bytes.size()), base);
    if (access.fault) throw *access.fault;
    if (!ok || !err.empty()) doc.fail("tinygltf: " + first_line(err));
    if (doc.model.asset.version.rfind("2.", 0) != 0) doc.fail("asset.version '" + doc.model.asset.version.substr(0, 20) + "' (expected 2.x)");
    // A file that requires an extension bounce does not read cannot be shown as meant (the
    // spec asks loaders to refuse it). A texture transform changes no texture's mean.
    for (const std::string& ext : doc.model.extensionsRequired)
        if (ext != "KHR_lights_punctual" && ext != "KHR_materials_emissive_strength" && ext != "KHR_texture_transform")
            doc.fail("extensionsRequired: '" + ext.substr(0, 60) +
                     "' is not supported (bounce reads KHR_lights_punctual and KHR_materials_emissive_strength)");
    return doc;
}

namespace {

// Where the elements of an accessor lie in its buffer, every byte checked to be there.
struct element_range {
    const unsigned char* first = nullptr;
    std::size_t count = 0, stride = 0;
};

struct accessor_kind {
    int type;                                // TINYGLTF_TYPE_*
    std::initializer_list<int> components;   // accepted TINYGLTF_COMPONENT_TYPE_*
    const char* expected;                    // for messages
};

element_range locate(const gltf_document& doc, int index, const std::string& user, const accessor_kind& kind) {
    const auto& m = doc.model;
    if (index < 0 || std::size_t(index) >= m.accessors.size())
        doc.fail(user + ": accessor " + std::to_string(index) + " does not exist (the file has " +
                 std::to_string(m.accessors.size()) + ")");
    const tinygltf::Accessor& a = m.accessors[std::size_t(index)];
    const std::string name = user + " (" + at("accessors", index) + ")";
    if (a.type != kind.type || std::find(kind.components.begin(), kind.components.end(), a.componentType) == kind.components.end())
        doc.fail(name + ": type " + std::to_string(a.type) + ", component type " + std::to_string(a.componentType) +
                 "; expected " + kind.expected);
    if (a.sparse.isSparse) doc.fail(name + ": sparse accessors are not supported");
    if (a.count == 0) doc.fail(name + ": count 0");
    if (a.bufferView < 0 || std::size_t(a.bufferView) >= m.bufferViews.size())
        doc.fail(name + ": bufferView " + std::to_string(a.bufferView) + " does not exist (accessors without one are not supported)");
    const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
    const std::string view = at("bufferViews", a.bufferView);
    if (v.buffer < 0 || std::size_t(v.buffer) >= m.buffers.size()) doc.fail(view + ": buffer " + std::to_string(v.buffer) + " does not exist");
    const std::size_t buffer_size = m.buffers[std::size_t(v.buffer)].data.size();
    if (v.byteOffset > buffer_size || v.byteLength > buffer_size - v.byteOffset)
        doc.fail(view + ": bytes [" + std::to_string(v.byteOffset) + ", +" + std::to_string(v.byteLength) + ") lie beyond " +
                 at("buffers", v.buffer) + " (" + std::to_string(buffer_size) + " bytes)");
    const auto component = std::size_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType)));
    const std::size_t element = component * std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(a.type)));
    const std::size_t stride = v.byteStride == 0 ? element : v.byteStride;
    if (stride < element || stride > 252 || stride % component != 0)
        doc.fail(view + ": byteStride " + std::to_string(v.byteStride) + " does not fit " + std::to_string(element) +
                 "-byte elements (at most 252, a multiple of the component size)");
    // Elements 0..count-1 end at byteOffset + (count - 1) stride + element, within the view.
    if (a.byteOffset > v.byteLength || element > v.byteLength - a.byteOffset ||
        a.count - 1 > (v.byteLength - a.byteOffset - element) / stride)
        doc.fail(name + ": " + std::to_string(a.count) + " elements from byte " + std::to_string(a.byteOffset) +
                 " do not fit " + view + " (" + std::to_string(v.byteLength) + " bytes, stride " + std::to_string(stride) + ")");
    return {m.buffers[std::size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset, a.count, stride};
}

template <class T>
[[maybe_unused]] T load(const unsigned char* p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

[[maybe_unused]] double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

}  // namespace

std::vector<glm::dvec3> read_vec3_accessor(const gltf_document& doc, int index, const std::string& user, bool finite) {
    const element_range r = locate(doc, index, user, {TINYGLTF_TYPE_VEC3, {TINYGLTF_COMPONENT_TYPE_FLOAT}, "VEC3 of FLOAT (5126)"});
    std::vector<glm::dvec3> out(r.count);
    for (std::size_t i = 0; i < r.count; ++i) {
        const unsigned char* p = r.first + i * r.stride;
        for (int c = 0; c < 3; ++c) out[i][c] = double(load<float>(p + 4 * c));
        if (finite && !(std::isfinite(out[i].x) && std::isfinite(out[i].y) && std::isfinite(out[i].z)))
            doc.fail(user + " (" + at("accessors", index) + "): element " + std::to_string(i) + " is not finite (NaN or infinity)");
    }
    return out;
}

std::vector<std::uint32_t> read_index_accessor(const gltf_document& doc, int index, const std::string& user) {
    const element_range r = locate(doc, index, user,
                                   {TINYGLTF_TYPE_SCALAR,
                                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                                    "SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT (5121, 5123, 5125)"});
    const int type = doc.model.accessors[std::size_t(index)].componentType;
    std::vector<std::uint32_t> out(r.count);
    for (std::size_t i = 0; i < r.count; ++i) {
        const unsigned char* p = r.first + i * r.stride;
        out[i] = type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? *p
                 : type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? load<std::uint16_t>(p)
                                                                  : load<std::uint32_t>(p);
    }
    return out;
}

glm::dvec3 base_colour_mean(const gltf_document& doc, int texture, const std::string& user) {
    const auto& m = doc.model;
    if (texture < 0 || std::size_t(texture) >= m.textures.size())
        doc.fail(user + ": texture " + std::to_string(texture) + " does not exist");
    const int source = m.textures[std::size_t(texture)].source;
    if (source < 0 || std::size_t(source) >= m.images.size())
        doc.fail(at("textures", texture) + ".source: image " + std::to_string(source) + " does not exist");
    const tinygltf::Image& encoded = m.images[std::size_t(source)];
    const std::string image = at("images", source);
    if (encoded.image.empty() || encoded.image.size() > std::size_t(INT_MAX)) doc.fail(image + ": no image data");
#ifdef TINYGLTF_NO_STB_IMAGE
    doc.fail(image + ": this build decodes no images (TINYGLTF_NO_STB_IMAGE)");
#else
    tinygltf::Image img;
    std::string err, warn;
    if (!tinygltf::LoadImageData(&img, source, &err, &warn, 0, 0, encoded.image.data(), int(encoded.image.size()), nullptr))
        doc.fail(image + ": cannot decode (" + first_line(err) + ")");
    const std::size_t bytes_per = img.bits == 16 ? 2 : 1;
    if (img.width <= 0 || img.height <= 0 || img.component != 4 || (img.bits != 8 && img.bits != 16) ||
        img.image.size() != std::size_t(img.width) * std::size_t(img.height) * 4 * bytes_per)
        doc.fail(image + ": the decoder returned an unexpected layout");
    std::array<double, 256> lut8{};
    for (int i = 0; i < 256; ++i) lut8[std::size_t(i)] = srgb_to_linear(i / 255.0);
    glm::dvec3 sum(0.0);
    const std::size_t texels = std::size_t(img.width) * std::size_t(img.height);
    for (std::size_t t = 0; t < texels; ++t)
        for (int c = 0; c < 3; ++c) {
            const std::size_t k = (4 * t + std::size_t(c)) * bytes_per;
            sum[c] += bytes_per == 1 ? lut8[img.image[k]] : srgb_to_linear(load<std::uint16_t>(&img.image[k]) / 65535.0);
        }
    return sum / double(texels);
#endif
}

}  // namespace bounce::io::detail
