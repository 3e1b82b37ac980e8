// The provenance of a run: commit, date, CPU, cores, GL renderer, Embree's kernels.
#include <bounce/study/provenance.hpp>

#include <embree3/rtcore_config.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string_view>
#include <thread>

namespace bounce::study {

namespace fs = std::filesystem;

namespace {

// Runs `command` and returns its first line of output ("" on failure).
std::string first_line_of(const std::string& command) {
    std::string out;
    if (FILE* p = popen(command.c_str(), "r")) {
        std::array<char, 256> buf{};
        if (std::fgets(buf.data(), int(buf.size()), p)) out = buf.data();
        while (std::fgets(buf.data(), int(buf.size()), p)) {
        }
        pclose(p);
    }
    while (!out.empty() && (out.back() == '\n' || out.back() == ' ' || out.back() == '\r')) out.pop_back();
    return out;
}

std::string quoted(const fs::path& p) {
    std::string s = "'";
    for (char c : p.string()) s += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return s + "'";
}

std::string source_commit(const fs::path& dir) {
    const std::string git = "git -C " + quoted(dir);
    const std::string hash = first_line_of(git + " rev-parse --short HEAD 2>/dev/null");
    if (hash.empty()) return "unknown";
    const std::string dirty = first_line_of(git + " status --porcelain --untracked-files=no 2>/dev/null");
    return dirty.empty() ? hash : hash + "+dirty";
}

std::string cpu_model() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            if (colon != std::string::npos && colon + 2 <= line.size()) return line.substr(colon + 2);
        }
    return "unknown";
}

std::string utc_now() {
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

// The `isa` or `max_isa` value of an Embree configuration string, or "".
std::string configured_isa(std::string_view config) {
    for (std::string_view key : {"max_isa=", "isa="}) {
        std::size_t at = 0;
        while ((at = config.find(key, at)) != std::string_view::npos) {
            if (at == 0 || config[at - 1] == ',' || config[at - 1] == ' ') {
                const std::size_t begin = at + key.size(), end = config.find(',', begin);
                return std::string(key.substr(0, key.size() - 1)) + " " +
                       std::string(config.substr(begin, end == std::string_view::npos ? end : end - begin));
            }
            at += key.size();
        }
    }
    return {};
}

std::string embree_kernels() {
    const char* env = std::getenv("BOUNCE_EMBREE_CONFIG");
    std::string isa = env ? configured_isa(env) : std::string();
    if (isa.empty()) {
#if defined(__x86_64__) || defined(__i386__)
        __builtin_cpu_init();
        if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") &&
            __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
            isa = "AVX-512 (SKX)";
        else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2"))
            isa = "AVX2";
        else if (__builtin_cpu_supports("avx"))
            isa = "AVX";
        else if (__builtin_cpu_supports("sse4.2"))
            isa = "SSE4.2";
        else
            isa = "SSE2";
#else
        isa = "unknown";
#endif
    }
    return isa + ", Embree " RTC_VERSION_STRING;
}

}  // namespace

nlohmann::ordered_json provenance::to_json() const {
    nlohmann::ordered_json j;
    j["commit"] = commit;
    j["date"] = date;
    j["cpu"] = cpu;
    j["cores"] = cores;
    if (!gl_renderer.empty()) j["gl_renderer"] = gl_renderer;
    j["embree_isa"] = embree_isa;
    return j;
}

provenance collect_provenance(const fs::path& source_dir, std::string gl_renderer) {
    provenance p;
    // This file is adapters/study/src/provenance.cpp of the tree it was built from.
    const fs::path dir = source_dir.empty() ? fs::path(__FILE__).parent_path().parent_path().parent_path().parent_path()
                                            : source_dir;
    p.commit = source_commit(dir);
    p.date = utc_now();
    p.cpu = cpu_model();
    p.cores = std::thread::hardware_concurrency();
    p.gl_renderer = std::move(gl_renderer);
    p.embree_isa = embree_kernels();
    return p;
}

}  // namespace bounce::study
