#pragma once
// Where the view's error is (issue 30, --oracle-out): the error of the solve's view split into
// the lights' direct light and the rest, and the best any lightmap of this atlas could do (an
// "oracle" lightmap: each texel the multi-bounce reference integrator's mean radiance over 4 x 4
// points of its texel square (planar charts' whole texels), else at its element's point, on each side the
// view sees, through the same bilinear lookup), against the reference and a second one of
// another seed (their difference taking the references' noise out), and the oracle's own
// noise from two oracles of different seeds. Every error is relative to the reference's
// total (rms of luminance over the mask), so parts add in quadrature.
#include <bounce/embree/lightmap_view.hpp>
#include <bounce/embree/multi_bounce_reference.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/luminance.hpp>
#include <bounce/radiosity/shooters.hpp>
#include <bounce/study/multi_bounce_cache.hpp>

#include "report.hpp"
#include "view.hpp"

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <span>
#include <vector>

namespace bounce::examples {

// Per element and side (side-major: side * n + element), the oracle's B = pi L in all and
// of the direct light (bounce 0) alone, 0 where the view sees neither.
struct oracle_lightmaps {
    std::vector<glm::vec3> total, direct;
};

inline oracle_lightmaps oracle_values(const embree::accel& bvh, const scene_view& scene, const lightmap_atlas& atlas,
                                      const std::vector<std::uint8_t>& seen, std::uint32_t paths, std::uint64_t seed) {
    constexpr int k = 4;  // k x k points over a whole texel of a planar chart, as the lights' shot takes
    embree::multi_bounce_settings whole, partial;
    whole.paths = std::max<std::uint32_t>(1, paths / (k * k));
    partial.paths = paths;
    whole.seed = partial.seed = seed;
    const embree::multi_bounce_reference at_whole(bvh, scene, whole), at_partial(bvh, scene, partial);
    std::vector<std::uint8_t> is_whole = whole_texels(atlas);
    for (std::size_t e = 0; e < atlas.size(); ++e)  // a curved chart's texel square leaves its surface
        is_whole[e] = is_whole[e] && atlas.charts[atlas.chart[e]].planar;
    // Per chart, the triangle whose albedo's least channel is largest: the reference shades
    // with a triangle's albedo, rescaled below to the texel's (the mean over the chart).
    std::vector<std::uint32_t> shade(atlas.charts.size());
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        const lightmap_chart& ch = atlas.charts[c];
        float best = -1.f;
        for (std::uint32_t t = ch.first_triangle; t < ch.first_triangle + ch.triangle_count; ++t) {
            const glm::vec3 rho = scene.materials[scene.material_of[atlas.chart_triangles[t]]].albedo;
            if (std::min({rho.x, rho.y, rho.z}) > best) best = std::min({rho.x, rho.y, rho.z}), shade[c] = atlas.chart_triangles[t];
        }
    }
    const std::size_t n = atlas.size();
    oracle_lightmaps out{std::vector<glm::vec3>(2 * n, glm::vec3(0.f)), std::vector<glm::vec3>(2 * n, glm::vec3(0.f))};
    const float pi = float(std::numbers::pi);
    tbb::parallel_for(std::size_t(0), 2 * n, [&](std::size_t i) {
        const auto e = std::uint32_t(i % n);
        const int side = int(i / n);
        if (!seen[2 * atlas.chart[e] + std::size_t(side)]) return;
        const std::uint32_t tri = shade[atlas.chart[e]];
        const glm::vec3 n_side = side ? -atlas.normal[e] : atlas.normal[e];
        std::vector<glm::dvec3> bounces;
        glm::dvec3 total(0.0);
        const int kk = is_whole[e] ? k : 1;
        for (int a = 0; a < kk; ++a)
            for (int b = 0; b < kk; ++b) {
                const glm::vec3 p = is_whole[e] ? light_sample_point(atlas, e, a, b, k) : atlas.position[e];
                const auto& ref = is_whole[e] ? at_whole : at_partial;
                total += glm::dvec3(ref.radiance(p, n_side, tri, embree::derive_seed(seed, i, std::uint64_t(a * k + b)), &bounces));
            }
        // The reference shades with the triangle's albedo; the texel's is the chart's mean over it.
        const glm::vec3 rho = scene.materials[scene.material_of[tri]].albedo;
        const glm::vec3 scale = glm::vec3(rho.x > 0 ? atlas.albedo[e].x / rho.x : 0.f, rho.y > 0 ? atlas.albedo[e].y / rho.y : 0.f,
                                          rho.z > 0 ? atlas.albedo[e].z / rho.z : 0.f) * pi / float(kk * kk);
        out.total[i] = glm::vec3(total) * scale;
        out.direct[i] = bounces.empty() ? glm::vec3(0.f) : glm::vec3(bounces[0]) * scale;
    });
    return out;
}

// Luminance error of x against the mean of a and b (two seeds' estimates of one part), relative to
// the total reference's rms (ta, tb its two seeds): raw (against a alone, as the program's
// rel_rms) and with the references' noise taken out; `x_noise`, when given, is a second estimate
// of x of another seed, and its noise (of the mean of the two) is reported.
inline nlohmann::ordered_json part_error(const image<glm::vec3>& x, const image<glm::vec3>& a, const image<glm::vec3>& b,
                                         const image<glm::vec3>& ta, const image<glm::vec3>& tb, const image<float>& mask,
                                         const image<glm::vec3>* x_other = nullptr) {
    const auto lum = [](const glm::vec3& c) { return rec709_luminance<double, glm::dvec3>(glm::dvec3(c)); };
    double raw = 0, d = 0, noise = 0, ref_sq = 0, tnoise = 0, tsq = 0, xnoise = 0, n = 0;
    for (std::size_t y = 0; y < x.height(); ++y)
        for (std::size_t i = 0; i < x.width(); ++i) {
            if (mask(i, y) == 0.f) continue;
            const double lx = x_other ? 0.5 * (lum(x(i, y)) + lum((*x_other)(i, y))) : lum(x(i, y));
            const double la = lum(a(i, y)), lb = lum(b(i, y)), r = 0.5 * (la + lb);
            const double lta = lum(ta(i, y)), ltb = lum(tb(i, y));
            raw += (lx - la) * (lx - la);
            d += (lx - r) * (lx - r);
            noise += 0.25 * (la - lb) * (la - lb);
            tsq += lta * lta;
            ref_sq += 0.25 * (lta + ltb) * (lta + ltb);
            tnoise += 0.25 * (lta - ltb) * (lta - ltb);
            if (x_other) xnoise += 0.0625 * std::pow(lum(x(i, y)) - lum((*x_other)(i, y)), 2.0);
            n += 1;
        }
    const double s = ref_sq - tnoise;
    nlohmann::ordered_json j{{"rel_rms", std::sqrt(raw / tsq)}, {"rel_rms_noise_removed", std::sqrt(std::max(0.0, d - noise) / s)},
                             {"reference_noise", std::sqrt(noise / s)}};
    if (x_other) {
        j["own_noise"] = std::sqrt(xnoise / s);
        j["rel_rms_all_noise_removed"] = std::sqrt(std::max(0.0, d - noise - xnoise) / s);
    }
    return j;
}

// Per chart and side seen, the indirect part's squared error of the solver's and the oracle's
// lookup against the references' mean (luminance sums over its pixels), the largest first:
// where the solver's bounced light differs from the best lightmap's.
inline nlohmann::ordered_json indirect_by_chart(const std::vector<embree::lightmap_hit>& hits, const lightmap_atlas& atlas,
                                                const image<glm::vec3>& solver, const image<glm::vec3>& oracle,
                                                const image<glm::vec3>& a, const image<glm::vec3>& b, const image<float>& mask) {
    struct sums { double solver_sq = 0, oracle_sq = 0, solver = 0, oracle = 0, ref = 0; std::size_t pixels = 0; };
    std::vector<sums> per(2 * atlas.charts.size());
    const auto lum = [](const glm::vec3& c) { return double(rec709_luminance<double, glm::dvec3>(glm::dvec3(c))); };
    double total = 0;
    for (std::size_t i = 0; i < hits.size(); ++i) {
        const std::size_t x = i % solver.width(), y = i / solver.width();
        if (mask(x, y) == 0.f || hits[i].chart == lightmap_atlas::none) continue;
        sums& s = per[2 * hits[i].chart + (hits[i].back ? 1 : 0)];
        const double r = 0.5 * (lum(a(x, y)) + lum(b(x, y))), ls = lum(solver(x, y)), lo = lum(oracle(x, y));
        s.solver_sq += (ls - r) * (ls - r), s.oracle_sq += (lo - r) * (lo - r);
        s.solver += ls, s.oracle += lo, s.ref += r, ++s.pixels;
        total += (ls - r) * (ls - r);
    }
    std::vector<std::size_t> order(per.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) { return per[p].solver_sq > per[q].solver_sq; });
    nlohmann::ordered_json j = nlohmann::ordered_json::array();
    for (std::size_t k = 0; k < std::min<std::size_t>(40, order.size()); ++k) {
        const sums& s = per[order[k]];
        const lightmap_chart& ch = atlas.charts[order[k] / 2];
        j.push_back({{"chart", order[k] / 2}, {"back", order[k] % 2}, {"share", s.solver_sq / std::max(total, 1e-30)},
                     {"pixels", s.pixels}, {"solver_mean", s.solver / double(s.pixels)}, {"oracle_mean", s.oracle / double(s.pixels)},
                     {"ref_mean", s.ref / double(s.pixels)}, {"oracle_share", s.oracle_sq / std::max(total, 1e-30)},
                     {"planar", ch.planar}, {"triangles", ch.triangle_count},
                     {"normal", {ch.normal.x, ch.normal.y, ch.normal.z}}, {"origin", {ch.origin.x, ch.origin.y, ch.origin.z}}});
    }
    return j;
}

// Writes the split and the oracle (JSON) to `file`; `view` is the solve's lightmap view.
template <splits_direct Solver>
void write_split(const std::filesystem::path& file, const embree::accel& bvh, const io::scene& scene, const Solver& solver,
                 const embree::multi_bounce_settings& settings, const embree::multi_bounce_image& reference,
                 const image<float>& mask, const image<glm::vec3>& view, std::size_t w, std::size_t h) {
    const auto start = std::chrono::steady_clock::now();
    const lightmap_atlas& atlas = solver.atlas();
    const auto hits = embree::lightmap_hits(bvh, scene, atlas, scene.camera, w, h);
    embree::multi_bounce_settings second = settings;
    second.seed = settings.seed + 1;
    second.progress = {};
    const auto ref2 = study::cached_multi_bounce(bvh, scene, scene.camera, w, h, second);
    const image<glm::vec3>& ta = reference.radiance;
    const image<glm::vec3>& tb = ref2.radiance;
    const image<glm::vec3> direct = embree::direct_light_view(bvh, scene, hits, w, h, 256, settings.seed);
    image<glm::vec3> ia(w, h), ib(w, h);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) ia(x, y) = ta(x, y) - direct(x, y), ib(x, y) = tb(x, y) - direct(x, y);
    const auto lookup = [&](std::span<const glm::vec3> values) {  // values side-major, as oracle_lightmaps
        const std::size_t n = atlas.size();
        const auto f = atlas.to_fine_texels(values.subspan(0, n), 0, glm::vec3(0.f), true);
        const auto b = values.size() > n ? atlas.to_fine_texels(values.subspan(n, n), 0, glm::vec3(0.f), true) : f;
        return embree::lightmap_view(hits, w, h, atlas, f.view(), b.view(), 0);
    };
    const auto solver_side = [&](bool rest) {
        std::vector<glm::vec3> v;
        for (int side = 0; side < solver.sides(); ++side) {
            const auto d = direct_deposit(solver, side);
            const auto b = solver.display_radiosity(side);
            for (std::size_t i = 0; i < d.size(); ++i) v.push_back(rest ? b[i] - d[i] : d[i]);
        }
        return lookup(v);
    };
    const image<glm::vec3> solver_direct = solver_side(false), solver_rest = solver_side(true);
    // The direct+indirect view (embree::lightmap_direct_view): the lights per pixel, the rest looked up.
    scene_view lights_only = scene;
    lights_only.use_emission = false;
    image<glm::vec3> with_direct = embree::direct_light_view(bvh, lights_only, hits, w, h);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) with_direct(x, y) += solver_rest(x, y);
    nlohmann::ordered_json j;
    j["solver"] = {{"total", part_error(view, ta, tb, ta, tb, mask)},
                   {"direct", part_error(solver_direct, direct, direct, ta, tb, mask)},
                   {"indirect", part_error(solver_rest, ia, ib, ta, tb, mask)},
                   {"direct_indirect_view", part_error(with_direct, ta, tb, ta, tb, mask)},
                   {"direct_indirect_black_pixels", black_pixels(with_direct, ta, mask)}};
    std::vector<std::uint8_t> seen(2 * atlas.charts.size(), 0);
    for (const auto& hit : hits)
        if (hit.chart != lightmap_atlas::none) seen[2 * hit.chart + (hit.back ? 1 : 0)] = 1;
    const auto oa = oracle_values(bvh, scene, atlas, seen, settings.paths, 1001);
    const auto ob = oracle_values(bvh, scene, atlas, seen, settings.paths, 1002);
    std::vector<glm::vec3> ra(oa.total.size()), rb(ob.total.size());
    for (std::size_t i = 0; i < ra.size(); ++i) ra[i] = oa.total[i] - oa.direct[i], rb[i] = ob.total[i] - ob.direct[i];
    const auto va = lookup(oa.total), vb = lookup(ob.total), da = lookup(oa.direct), db = lookup(ob.direct);
    const auto ira = lookup(ra), irb = lookup(rb);
    j["oracle"] = {{"total", part_error(va, ta, tb, ta, tb, mask, &vb)},
                   {"direct", part_error(da, direct, direct, ta, tb, mask, &db)},
                   {"indirect", part_error(ira, ia, ib, ta, tb, mask, &irb)},
                   {"black_pixels", black_pixels(va, ta, mask)},
                   {"paths_per_texel", settings.paths}, {"points_per_whole_texel", 16}};
    {  // the direct+indirect view's black pixels: the element the lookup's nearest texel reads, its
       // bounced light in the solver and the oracle's (both seeds' mean), both sides' luminance
        const double mean = reference_mean(ta, mask);
        const std::size_t n = atlas.size();
        const auto lum = [](const glm::vec3& c) { return rec709_luminance<float, glm::vec3>(c); };
        const float pi = float(std::numbers::pi);
        const auto bs = solver.display_radiosity(0), bb = solver.display_radiosity(solver.sides() - 1);
        const auto ds = direct_deposit(solver, 0), db = direct_deposit(solver, solver.sides() - 1);
        nlohmann::ordered_json holes = nlohmann::ordered_json::array();
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t x = 0; x < w; ++x) {
                const embree::lightmap_hit& hit = hits[y * w + x];
                if (!black_pixel(with_direct, ta, mask, mean, x, y) || hit.chart == lightmap_atlas::none) continue;
                const auto tx = std::uint32_t(std::clamp(hit.uv.x, 0.f, float(atlas.width - 1)));
                const auto ty = std::uint32_t(std::clamp(hit.uv.y, 0.f, float(atlas.height - 1)));
                const std::int32_t e = atlas.element_at(tx, ty);
                if (e < 0) continue;
                const auto i = std::size_t(e), side = std::size_t(hit.back ? 1 : 0);
                holes.push_back({{"x", x}, {"y", y}, {"chart", hit.chart}, {"back", hit.back}, {"element", e},
                                 {"reference", lum(ta(x, y)) / mean}, {"reference_rest", lum(0.5f * (ia(x, y) + ib(x, y))) / mean},
                                 {"solver_rest_front", lum(bs[i] - ds[i]) / pi / mean}, {"solver_rest_back", lum(bb[i] - db[i]) / pi / mean},
                                 {"oracle_rest_seen", lum(0.5f * (ra[side * n + i] + rb[side * n + i])) / pi / mean},
                                 {"oracle_total_seen", lum(0.5f * (oa.total[side * n + i] + ob.total[side * n + i])) / pi / mean}});
            }
        j["black_pixels_direct_indirect"] = holes;
    }
    j["indirect_by_chart"] = indirect_by_chart(hits, atlas, solver_rest, ira, ia, ib, mask);
    j["direct_by_chart"] = indirect_by_chart(hits, atlas, solver_direct, da, direct, direct, mask);
    {
        image<glm::vec3> ref_rest(w, h);
        for (std::size_t y = 0; y < h; ++y)
            for (std::size_t x = 0; x < w; ++x) ref_rest(x, y) = 0.5f * (ia(x, y) + ib(x, y));
        const float exposure = io::auto_exposure(ref_rest.view(), mask.view());
        const auto stem = file.parent_path() / file.stem();
        io::write_png(stem.string() + "-rest-solver.png", solver_rest.view(), exposure);
        io::write_png(stem.string() + "-rest-reference.png", ref_rest.view(), exposure);
        io::write_png(stem.string() + "-rest-oracle.png", ira.view(), exposure);
    }
    j["elements"] = atlas.size();
    j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    io::write_text_file(file, j.dump(2) + "\n");
}

// write_split for a solver that keeps the lights' direct deposit apart (splits_direct: the CPU and the GL
// solver); any other throws naming --oracle-out.
template <class Solver>
void write_oracle(const std::filesystem::path& file, const embree::accel& bvh, const io::scene& scene, const Solver& solver,
                  const embree::multi_bounce_settings& settings, const embree::multi_bounce_image& reference,
                  const image<float>& mask, const image<glm::vec3>& view, std::size_t w, std::size_t h) {
    if constexpr (!splits_direct<Solver>) throw parameter_error("--oracle-out", "needs a solver that keeps the direct light apart");
    else write_split(file, bvh, scene, solver, settings, reference, mask, view, w, h);
}

}  // namespace bounce::examples
