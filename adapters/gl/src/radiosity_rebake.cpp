// gl::progressive_radiosity's re-bakes: the correction of radiosity/rebake.hpp, equation (2),
// made by the solver's own passes. A light's change is its old light shot with -1 times its
// intensity and its new one shot; a move's is every block-side's effective shot re-shot with
// -1 on the old geometry and +1 on the new, through masked distributions (keep_binding), as
// cpu::rebake_move corrects it. The GPU shoots every element per pass, so a re-shot costs one
// item buffer and one distribution whatever its receivers: the mask keeps the result exact
// (pairs whose delivery cannot change are left as they are), not the pass short. What the
// moved elements received is taken away by the same re-shots (the CPU solver, which keeps
// each element's gathered irradiance, subtracts it instead of re-shooting to them).
#include "radiosity_state.hpp"

namespace bounce::gl {

std::vector<glm::vec3> progressive_radiosity::state::read_sides(const texture& t) const {
    std::vector<glm::vec3> all;
    for (std::uint32_t side = 0; side < sides; ++side) {
        const auto v = read_elements(t, int(side));
        all.insert(all.end(), v.begin(), v.end());
    }
    return all;
}

void progressive_radiosity::state::write_sides(const texture& t, const std::vector<glm::vec3>& values) {
    // Padding and empty texels hold 0 in the solver's element textures (radiosity_texture()):
    // written whole, nothing needs reading back first.
    std::vector<float> all(std::size_t(4) * width * height * sides, 0.f);
    const std::size_t n = atlas.size();
    for (std::size_t j = 0; j < values.size(); ++j) {
        const std::size_t row = std::size_t(atlas.texel[j % n].y) + (j / n) * height;
        const std::size_t at = 4 * (row * width + atlas.texel[j % n].x);
        all[at] = values[j].x, all[at + 1] = values[j].y, all[at + 2] = values[j].z;
    }
    const detail::unpack_state unpack;
    glTextureSubImage2D(t.id(), 0, 0, 0, GLsizei(width), GLsizei(height * sides), GL_RGBA, GL_FLOAT, all.data());
    check_error("progressive_radiosity: writing a re-bake's correction");
}

void progressive_radiosity::state::upload_direct(const std::vector<glm::vec3>& direct) {
    if (!direct_texture) direct_texture = std::make_unique<texture>(texel_format::rgba32f, width, std::size_t(height) * sides);
    write_sides(*direct_texture, direct);
}

void progressive_radiosity::state::reshoot(std::uint32_t k, float sign, const std::vector<glm::vec3>& shot,
                                           const std::vector<std::uint32_t>& keep_bits) {
    const std::uint32_t block = std::uint32_t(k % blocks()), side = std::uint32_t(k / blocks());
    const std::size_t o = std::size_t(side) * atlas.size();
    auto start = clock_type::now();
    upload_near_tree(block, [&](std::uint32_t i) { return glm::dvec3(shot[o + i]) * double(sign); });
    if (!keep) keep = std::make_unique<buffer>(keep_bits.size() * sizeof(std::uint32_t));
    keep->write(0, keep_bits.data(), keep_bits.size() * sizeof(std::uint32_t));
    set_block_shot(block, side);
    draw_visibility();
    if (options.timed_stages) finish();
    timings.visibility_ms += ms_since(start);
    start = clock_type::now();
    distribute(shot_chart, true);
    if (options.timed_stages) finish();
    timings.distribution_ms += ms_since(start);
    // What the re-shot delivers (either sign) changes what was intercepted, not what was
    // emitted: the power it moves between intercepted and escaped.
    const reduction got = reduce();
    intercepted_power += got.intercepted;
    escaped -= got.intercepted;
    absorbed += got.absorbed;
}

namespace {

// Runs `shots` (light shots) and adds the change of the radiosity they made (every side,
// side-major) to `direct` (B once the lights were shot).
template <class State, class Shots>
void shoot_lights_into(State& st, std::vector<glm::vec3>& direct, const Shots& shots) {
    const auto before = st.read_sides(st.radiosity);
    shots();
    const auto after = st.read_sides(st.radiosity);
    for (std::size_t j = 0; j < direct.size(); ++j) direct[j] += after[j] - before[j];
}

// Every light of the scene shot with `sign`, into `direct`.
template <class State>
void reshoot_lights(State& st, float sign, std::vector<glm::vec3>& direct) {
    shoot_lights_into(st, direct, [&] {
        for (const packed_light& l : st.lights) st.shoot_light(l, sign);
    });
}

}  // namespace

radiosity_rebake_report progressive_radiosity::rebake_light(std::size_t index, const light& changed) {
    state& st = *s_;
    if (index >= st.lights.size())
        throw parameter_error("index", "is light " + std::to_string(index) + " of the scene's " +
                                           std::to_string(st.lights.size()) + " (point, spot, directional)");
    validate_lights(std::span<const light>(&changed, 1), "changed");
    const auto start = clock_type::now();
    radiosity_rebake_report r;
    r.unshot_before = unshot_fraction();
    shoot_lights_into(st, direct_, [&] {
        st.shoot_light(st.lights[index], -1.f);
        st.lights[index] = pack(changed);
        st.shoot_light(st.lights[index], 1.f);
    });
    st.upload_direct(direct_);
    st.reduce();
    st.timings.lights_ms += ms_since(start);
    r.unshot_after = unshot_fraction();
    r.ms = ms_since(start);
    return r;
}

radiosity_rebake_report progressive_radiosity::rebake_move(const scene_view& moved_scene, std::span<const std::uint32_t> moved,
                                                           const rigid_move& move, double share) {
    state& st = *s_;
    require(share > 0 && share <= 1, "share", "must lie in (0, 1]");
    move.validate();
    moved_scene.validate();
    require(moved_scene.triangles.size() == st.atlas.chart_of_triangle.size(), "moved_scene",
            "is not the solver's scene moved (triangle counts differ)");
    const auto start = clock_type::now();
    radiosity_rebake_report r;
    r.unshot_before = unshot_fraction();
    const std::vector<std::uint8_t> charts = moved_charts(st.atlas, moved);
    const moved_boxes boxes = boxes_of_move(moved_scene, moved, move);
    const std::size_t n = st.atlas.size(), blocks = st.blocks();
    std::vector<std::uint8_t> moved_element(n), moved_block(blocks);
    for (std::size_t i = 0; i < n; ++i) moved_element[i] = charts[st.atlas.chart[i]], r.moved_elements += moved_element[i];
    for (std::size_t b = 0; b < blocks; ++b) moved_block[b] = charts[st.atlas.chart[st.first[b]]];
    rebake_filter filter(st.atlas, st.first, st.centre, boxes, rebake_margin(boxes, move));
    const std::vector<glm::vec3> shot = st.effective_shot;
    const std::vector<std::uint8_t> chosen =
        chosen_rebake_shooters<glm::vec3>(st.atlas, st.first, std::span<const glm::vec3>(shot), st.sides, share, r.uncorrected);

    // One pass of re-shots: every block-side chosen and asked for by `take`, to the receivers
    // `keep(element, whole)` asks for (whole: the shooter moves).
    std::vector<std::uint32_t> bits((n + 31) / 32);
    const auto pass = [&](float sign, const auto& take, const auto& keep) {
        for (std::uint32_t k = 0; k < chosen.size(); ++k) {
            if (!chosen[k] || !take(k % blocks)) continue;
            const bool whole = moved_block[k % blocks] != 0;
            if (!whole) filter.begin(st.centre[k % blocks]);
            std::fill(bits.begin(), bits.end(), 0u);
            std::size_t pairs = 0;
            for (std::uint32_t i = 0; i < n; ++i)
                if (keep(k % blocks, i, whole)) bits[i >> 5] |= 1u << (i & 31u), ++pairs;
            if (!whole) r.pairs_tested += n;
            if (pairs == 0) continue;  // no delivery of this shooter can change
            st.reshoot(k, sign, shot, bits);
            ++r.shooters, r.pairs += pairs;
            if (whole) ++r.moved_shooters, r.moved_pairs += pairs;
        }
    };
    // The old geometry: every chosen block-side takes back what it delivered to the moved
    // elements and through the boxes; the moved ones, to every element.
    pass(-1.f, [](std::size_t) { return true; }, [&](std::size_t b, std::uint32_t i, bool whole) {
        return whole || moved_element[i] || filter.through(st.centre[b], i);
    });
    reshoot_lights(st, -1.f, direct_);
    // The move: the charts, the element attributes, the triangles drawn, the shooters' centres.
    move_charts(st.atlas, charts, move);
    st.upload_texel_attributes();
    st.place_triangles(moved_scene);
    st.place_shooters();
    reshoot_lights(st, 1.f, direct_);
    // The new geometry: the unmoved block-sides deliver to the moved elements and through the
    // boxes again.
    pass(1.f, [&](std::size_t b) { return moved_block[b] == 0; }, [&](std::size_t b, std::uint32_t i, bool) {
        return moved_element[i] || filter.through(st.centre[b], i);
    });
    // The moved block-sides have shot nothing now (S = 0, dB = B): the solve shoots it with
    // the new geometry. The power they had shot, counted as escaped when taken back, is unshot.
    const auto b_now = st.read_sides(st.radiosity);
    auto unshot_now = st.read_sides(st.unshot);
    glm::dvec3 returned(0.0);
    for (std::size_t k = 0; k < chosen.size(); ++k) {
        if (!chosen[k] || !moved_block[k % blocks]) continue;
        for (std::size_t j = (k / blocks) * n + st.first[k % blocks]; j < (k / blocks) * n + st.first[k % blocks + 1]; ++j) {
            returned += glm::dvec3(b_now[j] - unshot_now[j]) * double(st.atlas.area[j % n]);
            unshot_now[j] = b_now[j], st.effective_shot[j] = glm::vec3(0.f);
        }
    }
    st.write_sides(st.unshot, unshot_now);
    st.upload_direct(direct_);
    st.escaped -= returned;
    st.shot_power -= returned.x + returned.y + returned.z;
    st.reduce();
    r.unshot_after = unshot_fraction();
    r.ms = ms_since(start);
    return r;
}

}  // namespace bounce::gl
