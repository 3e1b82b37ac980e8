#include <bounce/study/memory_budget.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace bounce::study {

namespace {
// The number after `key` in a "key: value kB" file (/proc/meminfo, /proc/self/status), in
// bytes; -1 when absent.
double proc_kb(const char* file, const std::string& key) {
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

double file_number(const char* file) {
    std::ifstream in(file);
    double v = -1;
    return (in >> v) ? v : -1;  // "max" (no cgroup limit) reads as no number
}
}  // namespace

std::uint64_t available_memory_bytes() {
    double avail = proc_kb("/proc/meminfo", "MemAvailable:");
    if (avail < 0) avail = double(sysconf(_SC_AVPHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
    const double cg_max = file_number("/sys/fs/cgroup/memory.max"), cg_now = file_number("/sys/fs/cgroup/memory.current");
    if (cg_max > 0 && cg_now >= 0) avail = std::min(avail, cg_max - cg_now);
    rlimit lim{};
    const double mapped = std::max(0.0, proc_kb("/proc/self/status", "VmSize:"));
    for (const int which : {RLIMIT_AS, RLIMIT_DATA})
        if (getrlimit(which, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY) avail = std::min(avail, double(lim.rlim_cur) - mapped);
    return avail > 0 ? std::uint64_t(avail) : 0;
}

std::string format_bytes(double bytes) {
    char buf[64];
    if (bytes >= 1e12) std::snprintf(buf, sizeof buf, "%.3g TB", bytes / 1e12);
    else if (bytes >= 1e9) std::snprintf(buf, sizeof buf, "%.3g GB", bytes / 1e9);
    else std::snprintf(buf, sizeof buf, "%.3g MB", bytes / 1e6);
    return buf;
}

}  // namespace bounce::study
