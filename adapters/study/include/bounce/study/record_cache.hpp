#pragma once
/// \file record_cache.hpp
/// Saving and loading an irradiance cache together with the parameters that built it.
///
/// Records are view-independent, so a cache computed once serves every later camera and
/// every a; but not a different scene, sampler or radius clamp. The file stores those
/// parameters, and `load_records` refuses a file whose parameters differ from the caller's,
/// naming the first differing key.

#include <bounce/errors.hpp>
#include <bounce/cache/record.hpp>

#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

namespace bounce::study {

/// A cache file that cannot be read or written, is malformed, or was built with other
/// parameters. `file()` names it.
struct cache_error : bounce::error {
    cache_error(std::filesystem::path file, const std::string& what);
    const std::filesystem::path& file() const noexcept { return file_; }

private:
    std::filesystem::path file_;
};

/// Writes `records` and `parameters` (any JSON object: scene, sampler, strata, radius limits
/// ...) as JSON. Floats are written with enough digits to read back bit for bit.
void save_records(const std::filesystem::path& file, const std::vector<irradiance_record>& records,
                  const nlohmann::json& parameters);

/// Reads records saved by save_records; throws cache_error when the stored parameters are
/// not equal to `expected_parameters`, or the file is missing or malformed.
std::vector<irradiance_record> load_records(const std::filesystem::path& file,
                                            const nlohmann::json& expected_parameters);

}  // namespace bounce::study
