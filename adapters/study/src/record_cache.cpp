#include <bounce/study/record_cache.hpp>

#include <cmath>
#include <fstream>

namespace bounce::study {

cache_error::cache_error(std::filesystem::path file, const std::string& what)
    : bounce::error("bounce: cache '" + file.string() + "': " + what), file_(std::move(file)) {}

namespace {
constexpr const char* format_tag = "bounce-irradiance-cache-1";

nlohmann::json vec(const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

glm::vec3 vec(const std::filesystem::path& file, const nlohmann::json& j, std::size_t i, const char* field) {
    if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
        throw cache_error(file, "records[" + std::to_string(i) + "]." + field + ": expected 3 numbers");
    const glm::vec3 v(j[0].get<float>(), j[1].get<float>(), j[2].get<float>());
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        throw cache_error(file, "records[" + std::to_string(i) + "]." + field + ": non-finite value");
    return v;
}

// The first key whose value differs between two parameter objects, for the error message.
std::string first_difference(const nlohmann::json& stored, const nlohmann::json& expected) {
    for (auto it = expected.begin(); it != expected.end(); ++it)
        if (!stored.contains(it.key()) || stored[it.key()] != it.value())
            return it.key() + " (file: " + (stored.contains(it.key()) ? stored[it.key()].dump() : "absent") +
                   ", wanted: " + it.value().dump() + ")";
    for (auto it = stored.begin(); it != stored.end(); ++it)
        if (!expected.contains(it.key())) return it.key() + " (only in the file)";
    return "?";
}
}  // namespace

void save_records(const std::filesystem::path& file, const std::vector<irradiance_record>& records,
                  const nlohmann::json& parameters) {
    nlohmann::json j;
    j["format"] = format_tag;
    j["parameters"] = parameters;
    auto& arr = j["records"] = nlohmann::json::array();
    for (const auto& r : records) {
        if (!std::isfinite(r.radius) || r.radius <= 0.f)
            throw cache_error(file, "refusing to save a record with radius " + std::to_string(r.radius));
        nlohmann::json o = {{"p", vec(r.position)},
                            {"n", vec(r.normal)},
                            {"e", vec(r.irradiance)},
                            {"rot", {vec(r.rotation[0]), vec(r.rotation[1]), vec(r.rotation[2])}},
                            {"tr", {vec(r.translation[0]), vec(r.translation[1]), vec(r.translation[2])}},
                            {"r", r.radius}};
        if (std::isfinite(r.variance) && r.variance > 0.f) o["v"] = r.variance;  // absent: unknown (0)
        arr.push_back(std::move(o));
    }
    std::ofstream out(file);
    if (!out) throw cache_error(file, "cannot open for writing");
    out << j.dump() << '\n';
    if (!out) throw cache_error(file, "write failed");
}

std::vector<irradiance_record> load_records(const std::filesystem::path& file, const nlohmann::json& expected) {
    std::ifstream in(file);
    if (!in) throw cache_error(file, "cannot open for reading");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw cache_error(file, std::string("malformed JSON: ") + e.what());
    }
    if (!j.is_object() || j.value("format", "") != format_tag) throw cache_error(file, "not a bounce irradiance cache");
    if (!j.contains("parameters") || j["parameters"] != expected)
        throw cache_error(file, "built with other parameters: " +
                                    first_difference(j.value("parameters", nlohmann::json::object()), expected));
    if (!j.contains("records") || !j["records"].is_array()) throw cache_error(file, "records: expected an array");
    std::vector<irradiance_record> recs;
    const auto& arr = j["records"];
    for (std::size_t i = 0; i < arr.size(); ++i) {
        const auto& o = arr[i];
        if (!o.is_object() || !o.contains("p") || !o.contains("n") || !o.contains("e") || !o.contains("rot") ||
            !o.contains("tr") || !o.contains("r") || !o["rot"].is_array() || o["rot"].size() != 3 ||
            !o["tr"].is_array() || o["tr"].size() != 3 || !o["r"].is_number())
            throw cache_error(file, "records[" + std::to_string(i) + "]: missing or malformed field");
        irradiance_record r;
        r.position = vec(file, o["p"], i, "p");
        r.normal = vec(file, o["n"], i, "n");
        r.irradiance = vec(file, o["e"], i, "e");
        for (int c = 0; c < 3; ++c) {
            r.rotation[c] = vec(file, o["rot"][c], i, "rot");
            r.translation[c] = vec(file, o["tr"][c], i, "tr");
        }
        r.radius = o["r"].get<float>();
        if (!std::isfinite(r.radius) || r.radius <= 0.f)
            throw cache_error(file, "records[" + std::to_string(i) + "].r: radius must be positive");
        if (o.contains("v")) {
            if (!o["v"].is_number()) throw cache_error(file, "records[" + std::to_string(i) + "].v: expected a number");
            r.variance = o["v"].get<float>();
        }
        recs.push_back(r);
    }
    return recs;
}

}  // namespace bounce::study
