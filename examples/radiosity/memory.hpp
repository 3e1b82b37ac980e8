#pragma once
// The memory a run may take, checked before it allocates: the library's estimate of the atlas
// and solver (cpu::radiosity_memory_estimate) plus the program's images, against what this
// machine can give the process now.
#include "options.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/errors.hpp>
#include <bounce/io/scene.hpp>

#include <fmt/core.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

namespace bounce::examples {

namespace detail {
// The number after `key` in a "key: value kB" file (/proc/meminfo, /proc/self/status), in
// bytes; -1 when absent.
inline double proc_kb(const char* file, const std::string& key) {
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(key, 0) == 0) {
            std::istringstream rest(line.substr(key.size()));
            double kb = -1;
            rest >> kb;
            return kb * 1024;
        }
    return -1;
}
inline double file_number(const char* file) {
    std::ifstream in(file);
    double v = -1;
    return (in >> v) ? v : -1;
}
}  // namespace detail

/// Bytes this process can still allocate: the least of MemAvailable (/proc/meminfo; else
/// sysconf's available pages), the cgroup's memory.max less memory.current, and the address
/// space and data limits (ulimit -v, -d) less what the process has mapped already.
inline double available_memory_bytes() {
    double avail = detail::proc_kb("/proc/meminfo", "MemAvailable:");
    if (avail < 0) avail = double(sysconf(_SC_AVPHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
    const double cg_max = detail::file_number("/sys/fs/cgroup/memory.max"), cg_now = detail::file_number("/sys/fs/cgroup/memory.current");
    if (cg_max > 0 && cg_now >= 0) avail = std::min(avail, cg_max - cg_now);
    rlimit lim{};
    const double mapped = std::max(0.0, detail::proc_kb("/proc/self/status", "VmSize:"));
    for (const int which : {RLIMIT_AS, RLIMIT_DATA})
        if (getrlimit(which, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY) avail = std::min(avail, double(lim.rlim_cur) - mapped);
    return std::max(avail, 0.0);
}

/// Throws parameter_error naming --elements when the run's estimated peak exceeds what the
/// machine can give it, with both figures.
inline void check_memory(const options& o, const io::scene& scene) {
    double need = cpu::radiosity_memory_estimate(scene, atlas_options_for(o));
    if (o.visibility != "rays") {
        const double faces = o.visibility == "hemicube" ? 3 : 1;  // five faces of res x res/2 or res
        need += 112.0 * double(scene.triangles.size()) + faces * 12.0 * double(o.resolution) * double(o.resolution);
    } else {
        need += 150.0 * double(scene.triangles.size());  // Embree's own copy of the scene and its BVH
    }
    need += 4 * 12.0 * double(o.width) * double(o.height);  // view, reference, mask, versus
    const double have = available_memory_bytes();
    if (need > have)
        throw parameter_error("--elements", fmt::format("{} elements over {}'s {} triangles need about {:.1f} GiB (atlas, "
                                                        "solver, lightmaps), more than the {:.1f} GiB this machine can give "
                                                        "now; ask for fewer",
                                                        o.elements, scene.name, scene.triangles.size(), need / (1u << 30),
                                                        have / (1u << 30)));
}

}  // namespace bounce::examples
