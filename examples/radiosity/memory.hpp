#pragma once
// The memory a run may take, checked before it allocates: the library's estimate of the atlas
// and solver (cpu::radiosity_memory_estimate) plus the program's images, against what this
// machine can give the process now.
#include "options.hpp"

#include <bounce/cpu/radiosity.hpp>
#include <bounce/errors.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/memory_budget.hpp>

#include <fmt/core.h>
#include <string>

namespace bounce::examples {

/// Throws parameter_error naming --elements when the run's estimated peak exceeds what the
/// machine can give it, with both figures.
inline void check_memory(const options& o, const io::scene& scene) {
    double need = cpu::radiosity_memory_estimate(scene, atlas_options_for(o), !o.one_sided);
    if (o.visibility != visibility_kind::rays) {
        const double faces = o.visibility == visibility_kind::hemicube ? 3 : 1;  // five faces of res x res/2 or res
        need += 112.0 * double(scene.triangles.size()) + faces * 12.0 * double(o.resolution) * double(o.resolution);
    } else {
        need += 150.0 * double(scene.triangles.size());  // Embree's own copy of the scene and its BVH
    }
    need += 4 * 12.0 * double(o.width) * double(o.height);  // view, reference, mask, versus
    const double have = double(study::available_memory_bytes());
    if (need > have)
        throw parameter_error("--elements", fmt::format("{} elements over {}'s {} triangles need about {:.1f} GiB (atlas, "
                                                        "solver, lightmaps), more than the {:.1f} GiB this machine can give "
                                                        "now; ask for fewer",
                                                        o.elements, scene.name, scene.triangles.size(), need / (1u << 30),
                                                        have / (1u << 30)));
}

}  // namespace bounce::examples
