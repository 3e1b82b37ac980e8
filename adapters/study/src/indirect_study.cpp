#include <bounce/study/indirect_study.hpp>

#include <bounce/embree/rsm_unoccluded_reference.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/luminance.hpp>
#include <bounce/output.hpp>

#include <fmt/core.h>

#include <chrono>
#include <fstream>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

namespace bounce::study {

using json = nlohmann::ordered_json;

void check_indirect_reference_spp(std::uint32_t spp, std::string_view option) {
    if (spp < 4 || spp > (1u << 20) || spp % 2 != 0)
        throw parameter_error(std::string(option),
                              std::to_string(spp) +
                                  " rays per pixel: want an even number in [4, 1048576] (the unoccluded reference "
                                  "is two halves of equal size, whose difference measures its noise)");
}

indirect_references cached_indirect_references(const embree::accel& bvh, const io::scene& scene,
                                               const camera& cam, const gbuffer_view<float>& g, std::uint32_t spp,
                                               const std::filesystem::path& dir) {
    check_indirect_reference_spp(spp);
    check_cache_dir(dir);
    indirect_references r;
    r.spp = spp;
    embree::reference_settings rs;
    rs.hemisphere_samples = spp;
    auto t0 = std::chrono::steady_clock::now();
    r.occluded = cached_reference(bvh, scene, cam, g.width(), g.height(), rs, dir, &r.occluded_from_cache);
    r.occluded_ms = ms_since(t0);

    const std::string key =
        reference_cache_key(scene, cam, g.width(), g.height(), rs, bvh.owner().config()) + "-unoccluded-v1";
    const auto exr = dir / (key + ".exr"), meta = dir / (key + ".json");
    t0 = std::chrono::steady_clock::now();
    if (std::filesystem::exists(exr) && std::filesystem::exists(meta)) {
        try {
            image<glm::vec3> img = io::read_rgb(exr);
            const auto m = nlohmann::json::parse(std::ifstream(meta));
            if (img.width() == g.width() && img.height() == g.height()) {
                r.unoccluded = std::move(img);
                r.unoccluded_noise = m.at("noise_rel_rms").get<double>();
                r.unoccluded_from_cache = true;
                r.unoccluded_ms = ms_since(t0);
                return r;
            }
        } catch (const std::exception&) {
            // An unreadable entry is recomputed.
        }
    }
    embree::unoccluded_reference_settings us;
    us.hemisphere_samples = spp;
    auto u = embree::render_unoccluded_reference(bvh, scene.view(), g, us);
    r.unoccluded = std::move(u.indirect);
    r.unoccluded_noise = u.noise_rel_rms;
    r.unoccluded_ms = ms_since(t0);
    // The image first, then its description: an entry is read only when both exist.
    io::write_exr(exr, r.unoccluded.view());
    io::write_text_file(meta, json{{"scene", scene.name},
                                   {"width", g.width()},
                                   {"height", g.height()},
                                   {"samples", u.samples},
                                   {"noise_rel_rms", u.noise_rel_rms}}
                                      .dump(2) +
                                  "\n");
    return r;
}

image<glm::vec3> radiance_image(const gbuffer_view<float>& g, image_view<const glm::vec3> e) {
    require(e.width() == g.width() && e.height() == g.height(), "e", "size differs from the G-buffer");
    image<glm::vec3> out(g.width(), g.height());
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) out(x, y) = e(x, y);
    apply_output(output_quantity::radiance, image_view<const glm::vec3>(g.albedo), out.view());
    return out;
}

double ssd_intensity(image_view<const glm::vec3> a, image_view<const glm::vec3> b, image_view<const float> mask) {
    require(a.width() == b.width() && a.height() == b.height() && a.width() == mask.width() &&
                a.height() == mask.height(),
            "b", "images and mask differ in size");
    double sum = 0;
    for (std::size_t y = 0; y < a.height(); ++y)
        for (std::size_t x = 0; x < a.width(); ++x) {
            if (mask(x, y) == 0.f) continue;
            const glm::dvec3 d = glm::dvec3(a(x, y)) - glm::dvec3(b(x, y));
            const double i = 0.2989 * d.x + 0.5870 * d.y + 0.1140 * d.z;
            sum += i * i;
        }
    return sum;
}

std::string technique_name(indirect_technique t) { return t == indirect_technique::rsm_gather ? "rsm" : "sii"; }

std::string pattern_name(interleave_pattern p) { return std::to_string(p.n) + "x" + std::to_string(p.m); }

json indirect_run::to_json() const {
    json timings = json::object();
    for (const auto& s : timer.stages()) timings[s] = timer.median_ms(s);
    json j = {{"technique", technique_name(options.technique)},
              {"vpls", options.count},
              {"pattern", pattern_name(options.pattern)},
              {"energy_correct", options.energy_correct},
              {"vpls_used", last.vpls},
              {"timings_ms", timings},
              {"error",
               {{"rel_rms", vs_unoccluded.rel_rms},
                {"max_abs", vs_unoccluded.max_abs},
                {"sum_sq", vs_unoccluded.sum_sq},
                {"pixels", vs_unoccluded.pixels}}}};
    j["error"]["rel_rms_occluded"] = vs_occluded.rel_rms;
    if (vs_plain) {
        j["error"]["vs_plain"] = {{"ssd_intensity", plain_ssd}, {"rel_rms", vs_plain->rel_rms}};
        j["speedup_vs_plain"] = plain_total_ms / total_ms();
    }
    return j;
}

std::string indirect_run::summary() const {
    std::string s = fmt::format("{:3} {:5} {:>3} {:5}: total {:9.1f} ms (shade {:9.1f}), rel_rms {:.4f}, occluded {:.4f}",
                                technique_name(options.technique), options.count, pattern_name(options.pattern),
                                options.energy_correct ? "" : "thesis", total_ms(), timer.median_ms("shade"),
                                vs_unoccluded.rel_rms, vs_occluded.rel_rms);
    if (vs_plain) s += fmt::format(", vs plain {:.4f} (ssd {:.4g})", vs_plain->rel_rms, plain_ssd);
    return s;
}

indirect_run measure_indirect(const indirect_bench& bench, const indirect_options& options, const indirect_run* plain,
                              std::optional<int> repeat) {
    require(bool(bench.frame), "bench.frame", "is empty");
    require(bench.refs != nullptr, "bench.refs", "is null");
    const int n = repeat.value_or(bench.repeat);
    require(n >= 1, "repeat", "must be at least 1");
    options.validate();
    indirect_run r;
    r.options = options;
    image<glm::vec3> e(bench.g.width(), bench.g.height());
    for (int i = 0; i < n; ++i) {
        r.timer.add_sample("rsm", bench.rsm_ms);
        r.last = bench.frame(options, e.view());
        r.timer.add_sample("split", r.last.split_ms);
        r.timer.add_sample("shade", r.last.shade_ms);
        r.timer.add_sample("gather", r.last.gather_ms);
        r.timer.add_sample("blur", r.last.blur_ms);
        r.timer.add_sample("upsample", r.last.upsample_ms);
        r.timer.add_sample("total", r.last.total_ms());
    }
    r.radiance = radiance_image(bench.g, e.view());
    r.vs_unoccluded = compare_luminance(r.radiance.view(), bench.refs->unoccluded.view(), bench.mask);
    r.vs_occluded = compare_luminance(r.radiance.view(), bench.refs->occluded.indirect.view(), bench.mask);
    if (plain) {
        r.vs_plain = compare_luminance(r.radiance.view(), plain->radiance.view(), bench.mask);
        r.plain_ssd = ssd_intensity(r.radiance.view(), plain->radiance.view(), bench.mask);
        r.plain_total_ms = plain->total_ms();
    }
    return r;
}

double clamp_removed_fraction(const indirect_bench& bench, indirect_options options) {
    require(bool(bench.frame), "bench.frame", "is empty");
    options.visibility = indirect_visibility::none;
    image<glm::vec3> e(bench.g.width(), bench.g.height());
    const auto light = [&] {
        bench.frame(options, e.view());
        double sum = 0;
        for (std::size_t y = 0; y < e.height(); ++y)
            for (std::size_t x = 0; x < e.width(); ++x)
                if (bench.mask(x, y) > 0.f) sum += double(rec709_luminance<float, glm::vec3>(e(x, y)));
        return sum;
    };
    const double clamped = light();
    options.light.min_distance2 = 0.f;
    options.light.footprint_scale = 0.f;
    const double whole = light();
    return whole > 0 ? 1.0 - clamped / whole : 0.0;
}

json interleaving_study(const indirect_bench& bench, const indirect_options& base,
                        const std::function<void(const indirect_run&)>& on_run) {
    const std::vector<std::size_t> counts{64, 128, 256, 512, 768, 1024};
    const std::vector<interleave_pattern> patterns{{2, 2}, {2, 4}, {4, 4}, {8, 8}};
    json grid = json::array();
    std::map<std::pair<std::string, std::size_t>, indirect_run> plain;
    std::map<std::tuple<std::string, std::size_t, int, int>, indirect_run> inter;
    auto run = [&](indirect_technique t, std::size_t count, interleave_pattern p, bool energy_correct,
                   const indirect_run* partner, std::optional<int> repeat = {}) {
        indirect_options o = base;
        o.technique = t;
        o.count = count;
        o.pattern = p;
        o.energy_correct = energy_correct;
        indirect_run r = measure_indirect(bench, o, partner, repeat);
        if (on_run) on_run(r);
        grid.push_back(r.to_json());
        return r;
    };
    for (const auto t : {indirect_technique::rsm_gather, indirect_technique::sii}) {
        const std::string name = technique_name(t);
        for (std::size_t k : {16, 32}) run(t, k, {1, 1}, true, nullptr);
        for (std::size_t k : counts) {
            indirect_run p = run(t, k, {1, 1}, true, nullptr);
            for (const auto& pat : patterns) inter.emplace(std::make_tuple(name, k, pat.n, pat.m), run(t, k, pat, true, &p));
            plain.emplace(std::make_pair(name, k), std::move(p));
        }
        run(t, 4096, {1, 1}, true, nullptr, 1);
        if (t == indirect_technique::sii)
            for (std::size_t k : {128ul, 1024ul}) run(t, k, {4, 4}, false, &plain.at({name, k}));
    }
    // The targets, from this one run.
    const auto& sii44_1024 = inter.at({"sii", 1024, 4, 4});
    const auto& sii44_128 = inter.at({"sii", 128, 4, 4});
    const auto& rsm44_1024 = inter.at({"rsm", 1024, 4, 4});
    json targets;
    targets["rsm_speedup_8x8_1024"] = plain.at({"rsm", 1024}).total_ms() / inter.at({"rsm", 1024, 8, 8}).total_ms();
    targets["sii_speedup_8x8_1024"] = plain.at({"sii", 1024}).total_ms() / inter.at({"sii", 1024, 8, 8}).total_ms();
    targets["sii_vs_plain_rel_rms_4x4"] = {{"128", sii44_128.vs_plain->rel_rms}, {"1024", sii44_1024.vs_plain->rel_rms}};
    targets["sii_vs_plain_ssd_4x4"] = {{"128", sii44_128.plain_ssd}, {"1024", sii44_1024.plain_ssd}};
    targets["sii_over_rsm_vs_plain_rel_rms_4x4_1024"] = sii44_1024.vs_plain->rel_rms / rsm44_1024.vs_plain->rel_rms;
    targets["sii_over_rsm_vs_plain_ssd_4x4_1024"] = sii44_1024.plain_ssd / rsm44_1024.plain_ssd;
    for (const auto& j : grid)
        if (j["vpls"] == 4096) targets[j["technique"].get<std::string>() + "_rel_rms_plain_4096"] = j["error"]["rel_rms"];
    // Equal time: each interleaved run against the plain run with N M times fewer lights
    // (kept in `plain`, or in the grid for 16 and 32).
    json equal = json::array();
    for (const auto& [key, r] : inter) {
        const auto& [technique, k, n, m] = key;
        const std::size_t fewer = k / std::size_t(n * m);
        json partner;
        if (plain.count({technique, fewer})) {
            const auto& p = plain.at({technique, fewer});
            partner = {{"total_ms", p.total_ms()}, {"rel_rms", p.vs_unoccluded.rel_rms}};
        } else {
            for (const auto& j : grid)
                if (j["technique"] == technique && j["vpls"] == fewer && j["pattern"] == "1x1") {
                    partner = {{"total_ms", j["timings_ms"]["total"]}, {"rel_rms", j["error"]["rel_rms"]}};
                    break;
                }
        }
        if (partner.is_null()) continue;
        equal.push_back({{"technique", technique},
                         {"vpls", k},
                         {"pattern", pattern_name(r.options.pattern)},
                         {"total_ms", r.total_ms()},
                         {"rel_rms", r.vs_unoccluded.rel_rms},
                         {"plain_vpls", fewer},
                         {"plain_total_ms", partner["total_ms"]},
                         {"plain_rel_rms", partner["rel_rms"]}});
    }
    targets["equal_time"] = equal;
    return {{"grid", grid}, {"targets", targets}};
}

}  // namespace bounce::study
