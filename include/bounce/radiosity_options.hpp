#pragma once
/// \file radiosity_options.hpp
/// What the progressive radiosity solvers share whatever their backend: how they shoot
/// (radiosity_options), the time they spent per stage (radiosity_timings) and where a solve
/// stands (radiosity_progress). cpu::progressive_radiosity takes these as they are;
/// gl::radiosity_options extends radiosity_options with its item-buffer options.

#include <bounce/errors.hpp>

#include <cmath>
#include <cstddef>

namespace bounce {

/// How a solver shoots.
struct radiosity_options {
    bool shoot_blocks = true;      ///< substructuring: shoot per atlas block (true) or per element
    int shooters_per_step = 1;     ///< shooters taken from one choice, shot in turn (typical: 1-16;
                                   ///< the GL solver shoots one)
    bool ambient = false;          ///< display_radiosity adds the ambient term (Cohen et al. 1988)
    double near_field = 4;         ///< a block shoots as one disc to receivers farther than this many
                                   ///< times its side (sqrt of its area), else as its quadrants,
                                   ///< recursively; 0: always one disc (typical: 2-4)

    /// Throws parameter_error naming the option ("radiosity_options.near_field" ...).
    void validate() const {
        require(shooters_per_step >= 1 && shooters_per_step <= 4096, "radiosity_options.shooters_per_step",
                "must lie in [1, 4096]");
        require(near_field >= 0 && std::isfinite(near_field), "radiosity_options.near_field",
                "must be finite and non-negative");
    }
};

/// Time spent per stage since construction, milliseconds. The GL solver ends visibility and
/// distribution with glFinish when gl::radiosity_options::timed_stages is set (so the figures
/// are the GPU's time, not the driver's queueing); otherwise the GPU's work is counted where
/// the step waits for it, in choice_ms.
struct radiosity_timings {
    double lights_ms = 0;        ///< shooting point, spot and directional lights, their visibility included (construction)
    double visibility_ms = 0;    ///< visibility of the surface shots: item buffers (GL: reading the
                                 ///< shooter back, tessellating, drawing), ray casts
    double choice_ms = 0;        ///< choosing shooters (reduction; GL: it also sums the powers)
    double distribution_ms = 0;  ///< form factors and updates over the elements
    double subdivision_ms = 0;   ///< adaptive subdivision: the test and the refined atlas (CPU only)
};

/// Where a solve stands after a step.
struct radiosity_progress {
    std::size_t steps = 0, shots = 0;
    double unshot_fraction = 1;  ///< unshot power / emitted power (channel sums)
};

}  // namespace bounce
