#pragma once
/// \file radiosity.hpp
/// Progressive refinement radiosity on the CPU (Cohen et al. 1988, on textures as in Coombe
/// and Harris 2005, GPU Gems 2 ch. 39): `cpu::progressive_radiosity`, the solver a program or
/// a renderer drives with step() / solve() (a solve to a target with checkpoints, a time limit
/// and its checks: radiosity/solve.hpp).
///
/// One step: choose the shooter with the largest unshot power (a parallel reduction over the
/// shooters), prepare visibility from it (the caller's shot_visibility: an item buffer, ray
/// casts, or all_visible), then add the shot's radiosity to every element in front of it
/// (the kernel shot_radiosity of radiosity/kernels.hpp, the chapter's Listing 39-4) and zero the
/// shooter's unshot radiosity. A shooter is one element or, with substructuring (Cohen et al.
/// 1986; the chapter's section 39.4), one block of the atlas (block_texels^2 texels of one
/// chart) shooting its total unshot power from its area-weighted centroid as one disc.
/// Per shot the work is O(elements) over struct-of-arrays, with nothing stored per pair.
///
/// Lights: the scene's emissive triangles start with unshot radiosity E = pi L_e; point, spot
/// and directional lights are shot once, first, as direct irradiance (direct_light.hpp) times
/// visibility from the light (two hemispheres for a point light or a spot wider than 90
/// degrees, parallel rays for a directional light). Their power is counted as what reaches
/// the elements: emitted power = sum E_i A_i + sum of direct irradiance times area.
///
/// Outputs (output.hpp): radiosity() is the solver's unknown B (emission included);
/// output() and lightmap() give irradiance or radiance, direct or indirect or both. The direct
/// part is what the lights above deliver (direct_ per element); the indirect part is what
/// the shots delivered, kept as irradiance per element (gathered_), so that irradiance is
/// exact even where an albedo channel is 0.
///
/// Energy: with the disc form factor a shot hands out dB_s sum_r F_{r->s} V A_r, which need not
/// equal the shot power dB_s A_s (energy leaves open scenes; and the approximation is not
/// exactly conservative). Two bounds keep it from exceeding it (issue 30): the form factor
/// takes the receiver's area too (element_form_factor: A_r F_{r->s} <= A_s), and a shot whose
/// deliveries still sum above its power is scaled down to it (shot_scale), so each shot is
/// two passes, the incident radiosity per element (received_), then the scaled update; the
/// solve checks after every step that the unshot power fell. The solver keeps, in double per
/// channel, absorbed power (the (1 - rho) share of what each element intercepts) and escaped
/// power (shot power less intercepted power), so that absorbed + unshot + escaped = emitted
/// after every step, to rounding. Elements are two-sided by default (radiosity/sides.hpp).
///
/// Determinism: elements are updated by exactly one task each, and sums run over fixed chunks
/// of shooters added in chunk order, so results are bitwise the same for any thread count.

#include <bounce/cpu/radiosity_ambient.hpp>
#include <bounce/cpu/radiosity_item_buffer.hpp>
#include <bounce/errors.hpp>
#include <bounce/image.hpp>
#include <bounce/light.hpp>
#include <bounce/output.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/radiosity/shooter_groups.hpp>
#include <bounce/radiosity/shooters.hpp>
#include <bounce/radiosity/sides.hpp>
#include <bounce/cpu/radiosity_memory.hpp>
#include <bounce/radiosity/options.hpp>
#include <bounce/radiosity/solve.hpp>
#include <bounce/radiosity/subdivision.hpp>
#include <bounce/scene_view.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <numeric>
#include <span>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace bounce::cpu {

// The options, timings and progress are the core's (radiosity/options.hpp), as the GL's.
using bounce::radiosity_options;
using bounce::radiosity_progress;
using bounce::radiosity_timings;

/// The solver. `Real` is the type of the radiosity arrays and of the kernel's arithmetic
/// (float, as a GPU would; double for reference solutions). `Visibility` models
/// shot_visibility.
template <shot_visibility Visibility, floating Real = float>
class progressive_radiosity {
public:
    using vec = glm::vec<3, Real>;

    /// Copies `atlas` (subdivide() refines the copy) and keeps the visibility (moved in);
    /// `scene` is read only here (its lights). Throws parameter_error on bad options or an
    /// atlas not built from `scene`, radiosity_error when the scene's lights reach no
    /// surface's front side (check_lights_reach_surfaces, radiosity/solve.hpp).
    progressive_radiosity(const scene_view& scene, const lightmap_atlas& atlas, Visibility visibility,
                          radiosity_options options = {})
        : atlas_(atlas), visibility_(std::move(visibility)), options_(options) {
        options.validate();
        scene.validate();
        require(options.shooter_groups == 0 || casts_from_any_point, "radiosity_options.shooter_groups",
                "needs a visibility that casts rays from any point (visible_from: ray casts, all_visible); item "
                "buffers render from one point per shot");
        require(atlas.chart_of_triangle.size() == scene.triangles.size(), "atlas",
                "was not built from this scene (triangle counts differ)");
        const std::size_t n = atlas.size();
        sides_ = options.two_sided ? 2 : 1;
        radiosity_.assign(sides_ * n, vec(0));
        unshot_.assign(sides_ * n, vec(0));
        // Two-sided, an emitter emits on the side the reference integrator gives it (its
        // vertex normals' side, emission_sides); one-sided, on its front.
        if (sides_ == 2) emits_back_ = emission_sides(scene, atlas);
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t j = emits_on(i, 0) ? i : n + i;
            radiosity_[j] = vec(atlas.emission[i]);
            unshot_[j] = vec(atlas.emission[i]);
            emitted_ += glm::dvec3(atlas.emission[i]) * double(atlas.area[i]);
            total_area_ += double(atlas.area[i]);
            albedo_area_ += glm::dvec3(atlas.albedo[i]) * double(atlas.area[i]);
        }
        build_shooters();
        const auto start = clock::now();
        direct_.assign(sides_ * n, vec(0));
        gathered_.assign(sides_ * n, vec(0)), effective_shot_.assign(sides_ * n, vec(0));
        for (const light& l : scene.lights) lights_.push_back(pack(l));
        for (const packed_light& l : lights_) shoot_light(l, false);
        timings_.lights_ms = ms_since(start);
        refresh_powers();
        check_lights_reach_surfaces(scene, atlas_, emitted_, sides_ == 2);
    }

    /// One step: choose shooters_per_step shooters by unshot power and shoot each in turn.
    /// Returns false (and does nothing) when no unshot power is left.
    bool step() {
        auto start = clock::now();
        const bool grouped = !groups_.roots.empty();
        if (grouped) {
            // A group's power: its block-sides' (refreshed by the last distribution).
            group_power_.assign(groups_.size(), 0.0);
            for (std::size_t k = 0; k < power_.size(); ++k) group_power_[groups_.group_of_leaf[k]] += power_[k];
        }
        const std::vector<double>& power = grouped ? group_power_ : power_;
        const std::size_t count = std::min<std::size_t>(std::size_t(options_.shooters_per_step), power.size());
        std::vector<std::uint32_t> chosen;
        if (count == 1) {
            const auto best = largest_power(power);
            if (best.first > 0) chosen.push_back(best.second);
        } else {
            std::vector<std::uint32_t> order(power.size());
            std::iota(order.begin(), order.end(), std::uint32_t(0));
            const auto larger = [&](std::uint32_t a, std::uint32_t b) {
                return power[a] > power[b] || (power[a] == power[b] && a < b);
            };
            std::nth_element(order.begin(), order.begin() + std::ptrdiff_t(count - 1), order.end(), larger);
            order.resize(count);
            std::sort(order.begin(), order.end(), larger);
            for (const std::uint32_t k : order)
                if (power[k] > 0) chosen.push_back(k);
        }
        timings_.choice_ms += ms_since(start);
        if (chosen.empty()) return false;
        for (const std::uint32_t k : chosen) grouped ? shoot_group(k) : shoot(k);
        ++steps_;
        return true;
    }

    /// Steps until the unshot fraction is at most `fraction` (in [0, 1)) or nothing is left
    /// to shoot, calling `progress` after each step (return false from it to stop early).
    /// Returns the steps taken. The checks of solve(radiosity_solve_options) apply.
    std::size_t solve(double fraction, const std::function<bool(const radiosity_progress&)>& progress = {}) {
        require(fraction >= 0 && fraction < 1, "fraction", "must lie in [0, 1)");
        radiosity_solve_options o;
        o.converge = 1.0 - fraction;
        o.progress = progress;
        return solve(o).steps;
    }

    /// The solve of radiosity/solve.hpp: to `options.converge`, within `options.max_seconds`,
    /// with its progress and checkpoint callbacks (the clock paused during checkpoints).
    /// Throws radiosity_error when energy is created or every shot escapes without reaching
    /// a surface's front side, parameter_error on bad options.
    radiosity_solve_report solve(const radiosity_solve_options& options) {
        return bounce::detail::run_radiosity_solve(*this, options, [](std::size_t) { return std::size_t(0); });
    }

    /// The same with adaptive subdivision: subdivide(scene, subdivision) after each of the
    /// first `subdivide_steps` steps of this solve (inside its clock; the report counts the
    /// leaves split). `scene` is the scene the atlas was built from.
    radiosity_solve_report solve(const radiosity_solve_options& options, const scene_view& scene,
                                 const subdivision_options& subdivision, std::size_t subdivide_steps) {
        subdivision.validate();
        return bounce::detail::run_radiosity_solve(*this, options, [&](std::size_t step) {
            return step <= subdivide_steps ? subdivide(scene, subdivision) : std::size_t(0);
        });
    }

    /// Unshot power / emitted power, channels summed; 0 for a scene that emits nothing.
    double unshot_fraction() const noexcept {
        const double e = emitted_.x + emitted_.y + emitted_.z;
        return e > 0 ? unshot_total_ / e : 0.0;
    }

    /// Power per channel, W: emitted (surfaces and the direct light that reached elements),
    /// absorbed, escaped (see the file comment), and unshot (recomputed from the array).
    glm::dvec3 emitted_power() const noexcept { return emitted_; }
    glm::dvec3 absorbed_power() const noexcept { return absorbed_; }
    glm::dvec3 escaped_power() const noexcept { return escaped_; }
    /// Power that reached elements since construction (the lights' direct light and what
    /// every shot delivered, before visibility's losses are counted as escaped), W per channel.
    glm::dvec3 intercepted_power() const noexcept { return intercepted_; }
    glm::dvec3 unshot_power() const {
        glm::dvec3 s(0);
        const std::size_t n = atlas_.size();
        for (std::size_t i = 0; i < unshot_.size(); ++i) s += glm::dvec3(unshot_[i]) * double(atlas_.area[i % n]);
        return s;
    }

    /// Radiosity B per element of `side` (0: front, counter-clockwise; 1: back, two-sided
    /// only), W/m^2 per channel (emission included).
    std::span<const vec> radiosity(int side = 0) const { return side_span(radiosity_, side); }
    /// Unshot radiosity per element of `side`, W/m^2 per channel.
    std::span<const vec> unshot(int side = 0) const { return side_span(unshot_, side); }
    /// 2 when elements are two-sided (radiosity_options::two_sided), else 1.
    int sides() const noexcept { return int(sides_); }
    bool two_sided() const noexcept { return sides_ == 2; }

    /// The ambient radiosity (Cohen et al. 1988): 1 / (1 - rho_avg) times the mean unshot radiosity.
    glm::dvec3 ambient() const { return cohen_ambient(unshot_power(), total_area_, albedo_area_, sides()); }

    /// Per element, the light of `paths` as `quantity` (output.hpp): irradiance (W/m^2) or
    /// the radiance of the atlas's albedo (W/(m^2 sr)). Direct: the point, spot and
    /// directional lights' irradiance times visibility (as radiance, plus the emission
    /// L_e); indirect: what the shots delivered (emissive surfaces' light included), plus the
    /// ambient term when the options ask. Radiance of `all` is display_radiosity() / pi.
    /// `side`: 0 the front, 1 the back (two-sided solvers only); the emission is counted on
    /// the side that emits.
    std::vector<glm::vec3> output(output_quantity quantity = output_quantity::irradiance,
                                  light_paths paths = light_paths::indirect, int side = 0) const {
        const std::size_t n = atlas_.size(), o = n * std::size_t(checked_side(side));
        std::vector<glm::vec3> out(n);
        const bool direct = paths != light_paths::indirect, indirect = paths != light_paths::direct;
        const auto amb = ambient_field(indirect, side);
        for (std::size_t i = 0; i < out.size(); ++i) {
            const glm::vec3 e = (direct ? glm::vec3(direct_[o + i]) : glm::vec3(0.f)) +
                                (indirect ? glm::vec3(gathered_[o + i]) + amb[i] : glm::vec3(0.f));
            out[i] = quantity == output_quantity::irradiance ? e : lambertian_radiance<float, glm::vec3>(atlas_.albedo[i], e);
            if (quantity == output_quantity::radiance && direct && emits_on(i, side))
                out[i] += atlas_.emission[i] * float(1.0 / std::numbers::pi);
        }
        return out;
    }

    /// output(quantity, paths) laid out as the atlas at 2^level times its resolution
    /// (lightmap_atlas::to_fine_texels: unsplit regions interpolated from the base texels;
    /// level > 0 shows what adaptive subdivision added): the lightmap a renderer samples with
    /// the atlas's corner_uvs.
    image<glm::vec3> lightmap(output_quantity quantity = output_quantity::irradiance,
                              light_paths paths = light_paths::indirect, int level = 0, int side = 0) const {
        const auto values = output(quantity, paths, side);
        return atlas_.to_fine_texels(std::span<const glm::vec3>(values), level, glm::vec3(0.f), true);
    }

    /// Radiosity to display now on `side` (0 front, 1 back): B, plus rho times the ambient
    /// term when the options ask.
    std::vector<glm::vec3> display_radiosity(int side = 0) const {
        const auto b = radiosity(side);
        std::vector<glm::vec3> out(b.size());
        const auto amb = ambient_field(true, side);
        for (std::size_t i = 0; i < out.size(); ++i)
            out[i] = radiosity_with_ambient<float, glm::vec3>(glm::vec3(b[i]), atlas_.albedo[i], amb[i]);
        return out;
    }

    /// display_radiosity (B, W/m^2) of `side` laid out as lightmap() lays outputs out: what
    /// embree::lightmap_view takes (the back's for the views of back sides).
    image<glm::vec3> radiosity_lightmap(int level = 0, int side = 0) const {
        const auto values = display_radiosity(side);
        return atlas_.to_fine_texels(std::span<const glm::vec3>(values), level, glm::vec3(0.f), true);
    }

    const radiosity_timings& timings() const noexcept { return timings_; }
    radiosity_progress progress() const noexcept {
        return {steps_, shots_, unshot_fraction(), 0.0, indirect_unshot_fraction()};
    }
    /// Of the power the surfaces reflect, the share still to shoot, its bounces to come
    /// included (radiosity/options.hpp): the convergence measure that counts bounced light.
    double indirect_unshot_fraction() const noexcept {
        const glm::dvec3 rho = albedo_area_ / total_area_;
        return bounce::indirect_unshot_fraction(unshot_total_, shot_power_, (rho.x + rho.y + rho.z) / 3.0);
    }
    /// Shooters: groups (radiosity_options::shooter_groups), else block-sides.
    std::size_t shooters() const noexcept { return groups_.roots.empty() ? power_.size() : groups_.size(); }
    /// The last shot: its shooter, its first element, the element that took the most of it
    /// and its share, and the scale that kept its delivered power within its own
    /// (radiosity/shooters.hpp, shot_scale; 1 unless the form factors summed above 1).
    const radiosity_shot_record& last_shot() const noexcept { return last_shot_; }
    /// Shots whose form factors summed above 1 and were scaled down to deliver their power.
    std::size_t clamped_shots() const noexcept { return clamped_shots_; }
    const lightmap_atlas& atlas() const noexcept { return atlas_; }
    Visibility& visibility() noexcept { return visibility_; }

    /// Adaptive subdivision (radiosity/subdivision.hpp): splits the leaves whose radiosity
    /// fails the test, gives each child element its parent's radiosity and unshot radiosity
    /// (power is unchanged: children's areas add up to their parent's), and rebuilds the
    /// shooters. Point, spot and directional lights are then evaluated again at the children
    /// (their direct light is known in closed form, so it is re-gathered rather than
    /// inherited): each child's radiosity and unshot radiosity change by rho times the change
    /// of its direct irradiance, and that power is added to the emitted (and its 1 - rho
    /// share to the absorbed) power, so the balance still holds. `scene` is the scene the
    /// atlas was built from. Returns the leaves split.
    /// The chapter runs this test after every reconstruction pass; calling it every step or
    /// every few steps from the first shots on keeps most of the light at the finer level.
    std::size_t subdivide(const scene_view& scene, const subdivision_options& options) {
        const auto start = clock::now();
        // The test sees both sides' radiosity together (where two-sided elements are lit).
        std::vector<glm::vec3> b(atlas_.size());
        for (std::size_t i = 0; i < radiosity_.size(); ++i) b[i % b.size()] += glm::vec3(radiosity_[i]);
        const auto split = blocks_to_subdivide(atlas_, std::span<const glm::vec3>(b), options);
        if (!split.empty()) {
            atlas_refinement r = refine_lightmap_atlas(scene, atlas_, split);
            const std::size_t m = r.parent.size(), n = atlas_.size();
            std::vector<vec> radiosity(sides_ * m), unshot(sides_ * m), direct(sides_ * m), gathered(sides_ * m), shot(sides_ * m);
            for (std::size_t side = 0; side < sides_; ++side)
                for (std::size_t i = 0; i < m; ++i) {
                    const std::size_t to = side * m + i, from = side * n + r.parent[i];
                    radiosity[to] = radiosity_[from];
                    unshot[to] = unshot_[from];
                    direct[to] = direct_[from];
                    gathered[to] = gathered_[from];
                    shot[to] = effective_shot_[from];
                }
            atlas_ = std::move(r.atlas);
            radiosity_ = std::move(radiosity);
            unshot_ = std::move(unshot);
            direct_ = direct;
            gathered_ = std::move(gathered), effective_shot_ = std::move(shot);
            build_shooters();  // the distribution below walks the new shooters' elements
            if (!lights_.empty()) {
                regather_lights(direct);
                refresh_powers();
            }
        }
        timings_.subdivision_ms += ms_since(start);
        return split.size();
    }

private:
    template <class Solver> friend struct rebake_access;  // re-baking what changed (radiosity_rebake.hpp)
    using clock = std::chrono::steady_clock;

    // Shooters: the atlas's blocks, or one per element, once per side (shooter k is block
    // k % blocks on side k / blocks); the blocks' centres and areas, the shooters' powers.
    void build_shooters() {
        first_ = shooter_ranges(atlas_, options_.shoot_blocks);
        const std::size_t shooters = first_.size() - 1;
        centre_.resize(shooters);
        shooter_area_.resize(shooters);
        power_.resize(sides_ * shooters);
        for (std::size_t k = 0; k < shooters; ++k) {
            const shooter_disc disc = shooter_disc_of(atlas_, first_[k], first_[k + 1]);
            centre_[k] = disc.centre;
            shooter_area_[k] = Real(disc.area);
        }
        if (options_.shooter_groups != 0)  // -1: the budget derived from the scene (shooter_groups.hpp)
            groups_ = build_shooter_groups(atlas_, first_, sides_, std::size_t(std::max(options_.shooter_groups, 0)),
                                           {options_.group_discs, options_.near_field, options_.group_near_field});
        refresh_powers();
    }
    static double ms_since(clock::time_point t) { return std::chrono::duration<double, std::milli>(clock::now() - t).count(); }
    // Shooters per chunk of the distribution: fixed, so sums do not depend on threads.
    static constexpr std::size_t chunk = 64;

    struct chunk_sums {
        glm::dvec3 absorbed{0}, intercepted{0};
        double unshot = 0;
        double top_power = 0;            // the largest power one element intercepted (channels summed)
        std::uint32_t top_receiver = 0;  // that element
    };

    static double channel_sum(const vec& v) { return double(v.x) + double(v.y) + double(v.z); }

    // Largest (power, lowest index among equals): associative, so the reduction's grouping
    // does not change the answer.
    std::pair<double, std::uint32_t> largest_power(const std::vector<double>& power) const {
        using best = std::pair<double, std::uint32_t>;
        const auto better = [](const best& a, const best& b) {
            return (b.first > a.first || (b.first == a.first && b.second < a.second)) ? b : a;
        };
        return tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, power.size(), 1024), best{-1.0, 0},
            [&](const tbb::blocked_range<std::size_t>& r, best acc) {
                for (std::size_t k = r.begin(); k != r.end(); ++k) acc = better(acc, best{power[k], std::uint32_t(k)});
                return acc;
            },
            better);
    }

    void refresh_powers() {
        unshot_total_ = 0;
        const std::size_t blocks = first_.size() - 1, n = atlas_.size();
        for (std::size_t k = 0; k < power_.size(); ++k) {
            const std::size_t b = k % blocks, o = n * (k / blocks);
            double p = 0;
            for (std::uint32_t i = first_[b]; i < first_[b + 1]; ++i) p += channel_sum(glm::abs(unshot_[o + i])) * double(atlas_.area[i]);
            power_[k] = p;
            unshot_total_ += p;
        }
    }

    // Runs `receive(i, sums)` for every element, chunk by chunk of blocks in parallel,
    // refreshing each block's shooters' powers (with `refresh`, both sides); then adds the
    // chunks' sums in order.
    template <class Receive>
    chunk_sums for_elements(const Receive& receive, bool refresh = false) {
        const std::size_t blocks = first_.size() - 1, chunks = (blocks + chunk - 1) / chunk, n = atlas_.size();
        sums_.assign(chunks, chunk_sums{});
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t c = r.begin(); c != r.end(); ++c) {
                chunk_sums s;
                const std::size_t k1 = std::min(blocks, (c + 1) * chunk);
                for (std::size_t k = c * chunk; k < k1; ++k) {
                    double p[2] = {0, 0};
                    for (std::uint32_t i = first_[k]; i < first_[k + 1]; ++i) {
                        receive(i, s);
                        if (!refresh) continue;
                        for (std::size_t side = 0; side < sides_; ++side)
                            p[side] += channel_sum(glm::abs(unshot_[side * n + i])) * double(atlas_.area[i]);
                    }
                    if (!refresh) continue;
                    for (std::size_t side = 0; side < sides_; ++side) {
                        power_[side * blocks + k] = p[side];
                        s.unshot += p[side];
                    }
                }
                sums_[c] = s;
            }
        });
        chunk_sums total;
        for (const chunk_sums& s : sums_) {
            total.absorbed += s.absorbed;
            total.intercepted += s.intercepted;
            total.unshot += s.unshot;
            if (s.top_power > total.top_power) total.top_power = s.top_power, total.top_receiver = s.top_receiver;
        }
        if (refresh) unshot_total_ = total.unshot;
        return total;
    }
    template <class Receive> chunk_sums distribute(const Receive& receive) { return for_elements(receive, true); }

    // A shot in two passes: every element's incident radiosity from the shooter (form factors
    // and visibility, into received_), then, scaled so that the shot delivers at most its own
    // power (shot_scale), added to the receivers.
    void shoot(std::uint32_t k) {
        const lightmap_atlas& at = atlas_;
        // Block b's elements on `side`: they shoot into the hemisphere of that side's normal.
        const std::size_t blocks = first_.size() - 1, b = k % blocks, side = k / blocks;
        const std::uint32_t i0 = first_[b], i1 = first_[b + 1];
        vec* unshot = unshot_.data() + side * at.size();
        // The shooter's unshot power, summed over its elements; then zeroed, so its elements'
        // power (refreshed in the distribution) starts from 0. Its elements are kept for the
        // near field.
        glm::dvec3 power(0);
        for (std::uint32_t i = i0; i < i1; ++i) power += glm::dvec3(unshot[i]) * double(at.area[i]);
        build_near_tree(std::uint32_t(b), unshot);
        for (std::uint32_t i = i0; i < i1; ++i) shot_elements_.push_back({std::uint32_t(side * at.size() + i), unshot[i]}), unshot[i] = vec(0);
        const glm::vec3 normal = side == 0 ? at.normal[i0] : -at.normal[i0];

        auto start = clock::now();
        visibility_.begin_shot(shot_frame{centre_[b], normal, false, at.chart[i0]});
        timings_.visibility_ms += ms_since(start);

        start = clock::now();
        finish_shot(power, gather_shot(at.chart[i0], vec(normal), [](std::uint32_t) { return true; }), start, k, i0);
    }

    // Pass 2 of a shot whose pass 1 (begun at `start`) found `incident`: the deliveries scaled
    // to the shot's `power` (shot_scale) and added, the balance's sums, the shot's record
    // (shooter `k`, its first element `first`).
    void finish_shot(const glm::dvec3& power, const glm::dvec3& incident, clock::time_point start, std::uint32_t k,
                     std::uint32_t first) {
        const glm::dvec3 scale = shot_scale(power, incident);
        const chunk_sums total = apply_shot(Real(scale.x), Real(scale.y), Real(scale.z));
        for (const auto& [j, u] : shot_elements_) effective_shot_[j] += u * vec(scale);
        shot_elements_.clear();
        shot_ambient_.record(options_, received_, scale, power, total.intercepted, total.absorbed, unshot_total_);
        timings_.distribution_ms += ms_since(start);
        absorbed_ += total.absorbed;
        escaped_ += power - total.intercepted;
        intercepted_ += total.intercepted;
        last_shot_ = {shots_, k, first, total.top_receiver,
                      total.top_power / std::max(bounce::detail::channel_total(glm::abs(power)), 1e-300), scale};
        if (scale != glm::dvec3(1.0)) ++clamped_shots_;
        shot_power_ += bounce::detail::channel_total(power);
        ++shots_;
    }

    // Pass 1 of a shot from the near-field tree near_ (normal `ns`, chart `chart`): each
    // element i with keep(i) (re-bakes ask only some), its incident radiosity sum_j dB_j F_{r->j} V (element_form_factor, the receiver's
    // area in it) into received_, and the power they intercept together (W per channel).
    // Two-sided, each node of the tree lights the receiver's side that faces it (its normal
    // flipped towards the node), so a receiver may take light on both sides from one shot.
    template <class Keep> glm::dvec3 gather_shot(std::uint32_t chart, const vec ns, const Keep& keep) {
        const lightmap_atlas& at = atlas_;
        const std::uint32_t root = std::uint32_t(near_.size() - 1);
        const Real near2 = Real(options_.near_field) * Real(options_.near_field);
        const std::size_t n = at.size();
        const bool two = sides_ == 2;
        received_.assign(sides_ * n, vec(0));
        const Visibility& vis = visibility_;
        const chunk_sums total = for_elements([&](std::uint32_t i, chunk_sums& s) {
            if (at.chart[i] == chart || !keep(i)) return;  // coplanar with the shooter: F = 0; or not asked
            const vec pr = vec(at.position[i]), nr = vec(at.normal[i]);
            const Real ar = Real(at.area[i]);
            vec incident(0), incident_back(0);
            // The block as one disc where the receiver is farther than near_field times its
            // side, else as its four quadrants, recursively, down to elements.
            std::array<std::uint32_t, 64> stack;
            std::size_t top = 0;
            stack[top++] = root;
            while (top > 0) {
                const near_node& node = near_[stack[--top]];
                if (node.child_count == 0 || !(near_field_opens<Real, vec>(pr, node.position, node.area, near2) > Real(0.5))) {
                    const Real side = receiving_side<Real, vec>(pr, nr, node.position, Real(two ? 1 : 0));
                    const bool back = side > Real(0.5);
                    const Real f = element_form_factor<Real, vec>(pr, side_normal<Real, vec>(nr, side), ar, node.position, ns, node.area);
                    if (f > Real(0)) (back ? incident_back : incident) += node.unshot * f;
                } else {
                    for (std::uint32_t c = 0; c < node.child_count; ++c) stack[top++] = node.first_child + c;
                }
            }
            const auto some = [](const vec& x) { return x != vec(0); };  // negative after a re-bake
            if (!some(incident) && !some(incident_back)) return;
            const Real v = Real(vis.visible(at.position[i], at.chart[i]));
            if (!(v > Real(0))) return;
            received_[i] = incident * v;
            if (two) received_[n + i] = incident_back * v;
            s.intercepted += (glm::dvec3(received_[i]) + glm::dvec3(incident_back * v)) * double(at.area[i]);
        });
        return total.intercepted;
    }

    // A grouped shot (radiosity/shooter_groups.hpp): group g's block-sides that hold unshot
    // power shoot together, as one hierarchy (the group's subtree of halves above each
    // block's near-field tree), in the same two passes as shoot(): every element's incident
    // radiosity, then the deliveries scaled to the shot's power (shot_scale) and added.
    void shoot_group(std::uint32_t g);  // radiosity_shots.hpp

    // The shot's hierarchy below static node `s` of the grouping: its block-sides with power,
    // each as its near-field tree (their unshot radiosity then zeroed), joined by the node's
    // two halves where both hold power. Adds the shot power (W per channel) to `power`; returns
    // the node's index in group_nodes_, or none when no leaf below holds power.
    std::uint32_t build_group_node(std::uint32_t s, glm::dvec3& power, std::uint32_t& first_element);  // radiosity_shots.hpp

    // Pass 1 of a grouped shot (the visibility drawn from its members: radiosity_shots.hpp).
    glm::dvec3 gather_group(std::uint32_t root);  // radiosity_shots.hpp

    // Pass 2: each element's received_ times the shot's scale (per channel) raises its
    // radiosity and unshot radiosity by rho times it (shot_radiosity's rho dB_s F V), refreshing
    // the shooters' powers; the sums of what was intercepted and absorbed, and the receiver
    // that took the most.
    chunk_sums apply_shot(Real sx, Real sy, Real sz) {
        const lightmap_atlas& at = atlas_;
        const vec scale(sx, sy, sz);
        const std::size_t n = at.size();
        return distribute([&](std::uint32_t i, chunk_sums& s) {
            for (std::size_t j = i; j < sides_ * n; j += n) {
                if (received_[j] == vec(0)) continue;
                const vec incident = received_[j] * scale;
                const vec rho = vec(at.albedo[i]);
                const vec gain = rho * incident;
                radiosity_[j] += gain;
                unshot_[j] += gain;
                gathered_[j] += incident;
                const glm::dvec3 intercepted = glm::dvec3(incident) * double(at.area[i]);
                s.intercepted += intercepted;
                s.absorbed += (glm::dvec3(1.0) - glm::dvec3(rho)) * intercepted;
                const double taken = bounce::detail::channel_total(glm::abs(intercepted));
                if (taken > s.top_power) s.top_power = taken, s.top_receiver = i;
            }
        });
    }

    // The lights' direct irradiance at every element of the refined atlas, against what the
    // elements inherited (`inherited`): the difference is added as described at subdivide().
    // Elements that were not split get bitwise their old value (same visibility, same sums).
    void regather_lights(const std::vector<vec>& inherited);  // radiosity_shots.hpp

    // Direct light from one light: each element's irradiance E (direct_light.hpp) times
    // visibility, on the side facing the light, becomes incident power and rho E its first
    // radiosity (only direct_ with `measure_only`, regather_lights); light_samples^2 points of
    // whole texels with options.light_samples.
    void shoot_light(const packed_light& l, bool measure_only);  // radiosity_shots.hpp

    lightmap_atlas atlas_;
    Visibility visibility_;
    radiosity_options options_;
    std::vector<vec> radiosity_, unshot_;
    std::vector<vec> direct_;             // direct irradiance from lights_ per element (W/m^2)
    std::vector<vec> gathered_;           // irradiance the shots delivered per element (W/m^2)
    // Per element-side, the unshot radiosity its shots shot, each times its shot's scale
    // (shot_scale): B = E + rho F effective_shot_ (= B - dB where no shot was scaled), what
    // the re-bakes re-shoot (radiosity_rebake.hpp); the shot's elements wait in shot_elements_.
    std::vector<vec> effective_shot_;
    std::vector<std::pair<std::uint32_t, vec>> shot_elements_;
    std::vector<packed_light> lights_;    // the scene's point, spot and directional lights
    std::vector<std::uint32_t> first_;
    std::vector<glm::vec3> centre_;
    std::vector<Real> shooter_area_;
    std::vector<double> power_;
    std::vector<chunk_sums> sums_;
    std::vector<vec> received_;  // a shot's incident radiosity per element, before its scale (W/m^2)
    radiosity_shot_record last_shot_;
    std::size_t clamped_shots_ = 0;
    // The shooter's near-field tree: its elements, then groups of 2 x 2, 4 x 4 ... cells of
    // its grid (the chapter's mipmap pyramid of the residual texture), the whole block last.
    // A node's unshot radiosity is the area-weighted mean of its elements', so every level
    // carries the same power.
    struct near_node {
        vec position;
        Real area;
        vec unshot;
        std::uint32_t first_child = 0, child_count = 0;
    };
    std::vector<near_node> near_;
    // Grouped shooters (radiosity_options::shooter_groups): the grouping, the groups' powers
    // (refreshed each step from power_), and a grouped shot's hierarchy, children by links_.
    struct group_node {
        vec position;
        Real area, size2;  // size2: the square of the node's extent, for the near-field test
        vec unshot, normal;
        Real cone_sin;     // the members' normal cone (0 for a block's nodes: one plane)
        std::uint32_t first_link = 0, child_count = 0, chart = shooter_group_node::none;
        Real power;        // channels summed, W: for drawing the ray's member
    };
    static constexpr bool casts_from_any_point = requires(const Visibility& v, const glm::vec3& p, std::uint32_t c) {
        { v.visible_from(p, c, p, c) } -> std::convertible_to<float>;
    };
    shooter_groups groups_;
    std::vector<double> group_power_;
    std::vector<group_node> group_nodes_;
    std::vector<std::uint32_t> links_;

    // The tree of radiosity/shooters.hpp (the GL solver builds the same) of block k, from the
    // unshot radiosity of one side (`unshot`, indexed by element).
    void build_near_tree(std::uint32_t k, const vec* unshot) {
        near_.clear();
        build_near_field_tree(
            atlas_, first_[k], first_[k + 1], options_.shoot_blocks, k,
            [&](std::uint32_t i) { return glm::dvec3(unshot[i]); },
            [&](glm::dvec3 centre, double node_area, glm::dvec3 mean_unshot, std::uint32_t first_child,
                std::uint32_t children) {
                near_.push_back({vec(centre), Real(node_area), vec(mean_unshot), first_child, children});
            });
    }
    // The two sides (radiosity_options::two_sided): radiosity_, unshot_, direct_, gathered_
    // and received_ hold sides_ x elements entries, the front's first; emits_back_ per chart,
    // whether its emission leaves from the back (two-sided only; emission_sides).
    std::size_t sides_ = 1;
    std::vector<std::uint8_t> emits_back_;
    std::span<const vec> side_span(const std::vector<vec>& v, int side) const {
        return std::span<const vec>(v).subspan(atlas_.size() * std::size_t(checked_side(side)), atlas_.size());
    }
    int checked_side(int side) const {
        require(side >= 0 && std::size_t(side) < sides_, "side", sides_ == 2 ? "must be 0 or 1" : "must be 0 (one-sided)");
        return side;
    }
    bool emits_on(std::size_t i, int side) const {
        const bool back = !emits_back_.empty() && emits_back_[atlas_.chart[i]];
        return back == (side == 1);
    }
    double unshot_total_ = 0, total_area_ = 0;
    double shot_power_ = 0;  // power shot by surfaces so far, channels summed, signed (W): sum of S A after a re-bake
    glm::dvec3 emitted_{0}, absorbed_{0}, escaped_{0}, intercepted_{0}, albedo_area_{0};
    radiosity_timings timings_;
    std::size_t steps_ = 0, shots_ = 0;
    shot_ambient_state<Real> shot_ambient_;  // the ambient term per element (Cohen's or the shots': radiosity_ambient.hpp)
    // Clamped where a re-bake's negative unshot power makes it negative: the indirect irradiance
    // shown (gathered_ plus the ambient) at least 0, as the converged one is (radiosity/rebake.hpp).
    std::vector<glm::vec3> ambient_field(bool on, int side) const {
        std::vector<glm::vec3> a = shot_ambient_.field(on, options_, *this, side);
        const std::size_t o = atlas_.size() * std::size_t(side);
        if (on && options_.ambient)
            for (std::size_t i = 0; i < a.size(); ++i) a[i] = glm::max(a[i], -glm::vec3(gathered_[o + i]));
        return a;
    }
};

}  // namespace bounce::cpu

#include <bounce/cpu/radiosity_shots.hpp>  // the members it defines out of the class
