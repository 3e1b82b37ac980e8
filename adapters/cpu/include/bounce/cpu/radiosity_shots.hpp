// The CPU solver's grouped shots (radiosity/shooter_groups.hpp, radiosity_options::shooter_groups)
// and the lights' shot, defined out of cpu::progressive_radiosity (radiosity.hpp, which includes
// this file at its end and documents each member where it is declared).
#pragma once

#include <bounce/cpu/radiosity.hpp>

namespace bounce::cpu {

template <shot_visibility Visibility, floating Real>
void progressive_radiosity<Visibility, Real>::shoot_group(std::uint32_t g) {
    glm::dvec3 power(0);
    group_nodes_.clear();
    links_.clear();
    std::uint32_t first_element = shooter_group_node::none;
    const std::uint32_t root = build_group_node(groups_.roots[g], power, first_element);
    if (root == shooter_group_node::none) return;
    const auto start = clock::now();
    finish_shot(power, gather_group(root), start, g, first_element);
}

template <shot_visibility Visibility, floating Real>
std::uint32_t progressive_radiosity<Visibility, Real>::build_group_node(std::uint32_t s, glm::dvec3& power,
                                                                      std::uint32_t& first_element) {
    const shooter_group_node& sn = groups_.nodes[s];
    const std::size_t blocks = first_.size() - 1, n = atlas_.size();
    if (sn.left == shooter_group_node::none) {
        const std::uint32_t k = groups_.leaves[sn.first];
        if (!(power_[k] > 0)) return shooter_group_node::none;
        const std::size_t b = k % blocks, side = k / blocks;
        const std::uint32_t i0 = first_[b], i1 = first_[b + 1], chart = atlas_.chart[i0];
        vec* unshot = unshot_.data() + side * n;
        const vec normal = side == 0 ? vec(atlas_.normal[i0]) : -vec(atlas_.normal[i0]);
        const std::uint32_t base = std::uint32_t(group_nodes_.size());
        build_near_field_tree(
            atlas_, i0, i1, options_.shoot_blocks, b, [&](std::uint32_t i) { return glm::dvec3(unshot[i]); },
            [&](glm::dvec3 centre, double node_area, glm::dvec3 mean_unshot, std::uint32_t first_child, std::uint32_t children) {
                group_node q{vec(centre), Real(node_area), Real(node_area), vec(mean_unshot), normal, Real(0),
                             std::uint32_t(links_.size()), children, chart, Real(bounce::detail::channel_total(glm::abs(mean_unshot)) * node_area)};
                for (std::uint32_t c = 0; c < children; ++c) links_.push_back(base + first_child + c);
                group_nodes_.push_back(q);
            });
        for (std::uint32_t i = i0; i < i1; ++i) {
            power += glm::dvec3(unshot[i]) * double(atlas_.area[i]);
            shot_elements_.push_back({std::uint32_t(side * n + i), unshot[i]}), unshot[i] = vec(0);
        }
        if (first_element == shooter_group_node::none) first_element = i0;
        return std::uint32_t(group_nodes_.size() - 1);
    }
    const std::uint32_t l = build_group_node(sn.left, power, first_element);
    const std::uint32_t r = build_group_node(sn.right, power, first_element);
    if (l == shooter_group_node::none || r == shooter_group_node::none) return l == shooter_group_node::none ? r : l;
    const group_node &a = group_nodes_[l], &c = group_nodes_[r];
    const Real area = a.area + c.area, weight = a.power + c.power;
    const glm::vec3 d = sn.hi - sn.lo;
    group_node q;
    // At the power's centroid (where the light leaves from), with the area-weighted mean
    // normal (not normalized: its length is the members' projected share, so the disc's
    // cosine sums theirs where all face the receiver, which the cone test ensures).
    q.position = weight > Real(0) ? (a.position * a.power + c.position * c.power) / weight
                                  : (a.position * a.area + c.position * c.area) / area;
    q.area = area;
    // The near-field test compares with near_field^2 size2: a block's node with its area,
    // this node with its half-diagonal times group_near_field / near_field.
    const double g = options_.near_field > 0 ? options_.group_near_field / options_.near_field : 0.0;
    q.size2 = std::max(area, Real(0.25 * g * g) * Real(glm::dot(d, d)));
    q.unshot = (a.unshot * a.area + c.unshot * c.area) / area;
    q.normal = (a.normal * a.area + c.normal * c.area) / area;
    q.cone_sin = Real(sn.cone_sin);
    q.first_link = std::uint32_t(links_.size());
    q.child_count = 2;
    q.chart = shooter_group_node::none;
    q.power = weight;
    links_.push_back(l);
    links_.push_back(r);
    group_nodes_.push_back(q);
    return std::uint32_t(group_nodes_.size() - 1);
}

// Pass 1 of a grouped shot: each element's incident radiosity from the hierarchy below
// `root` (a node as one disc unless the receiver is in its near field or some member may
// face away from it, then its children), into received_, times the visibility of rays
// from group_visibility_samples member elements, each drawn with probability its share
// of the receiver's light (a weighted reservoir over the discs taken, then down the tree
// by power): the mean of those rays is an unbiased estimate of the visible share of the
// receiver's (channel-summed) light. The draws are hash_uniform(shot, element, draw), so
// results do not depend on the thread count. Returns the intercepted power (W per channel).
template <shot_visibility Visibility, floating Real>
glm::dvec3 progressive_radiosity<Visibility, Real>::gather_group(std::uint32_t root) {
    const lightmap_atlas& at = atlas_;
    const Real near2 = Real(options_.near_field) * Real(options_.near_field);
    const std::size_t n = at.size();
    const bool two = sides_ == 2;
    const int samples = options_.group_visibility_samples;
    received_.assign(sides_ * n, vec(0));
    const Visibility& vis = visibility_;
    const std::uint64_t shot = shots_;
    const chunk_sums total = for_elements([&](std::uint32_t i, chunk_sums& s) {
        const vec pr = vec(at.position[i]), nr = vec(at.normal[i]);
        const Real ar = Real(at.area[i]);
        const std::uint32_t chart = at.chart[i];
        vec incident[2] = {vec(0), vec(0)};
        double weight[2] = {0, 0};
        std::array<std::uint32_t, 16> pick[2];
        std::uint64_t draws = 0;
        std::array<std::uint32_t, 256> stack;
        std::size_t top = 0;
        stack[top++] = root;
        while (top > 0) {
            const std::uint32_t j = stack[--top];
            const group_node& node = group_nodes_[j];
            if (node.chart == chart) continue;  // the receiver's own chart: coplanar, F = 0
            const vec r = pr - node.position;
            const Real d2 = glm::dot(r, r);
            bool open = node.child_count > 0 && d2 < near2 * node.size2;
            if (!open && node.child_count > 0) {
                // Every member faces away from the receiver: nothing to take. (Where only
                // some do, the node's normal sum counts their cosines against the others':
                // opening those nodes too made every receiver within the members' cone
                // of grazing open the group, 1.5 times the solve's time on Sponza.)
                const Real len = std::sqrt(glm::dot(node.normal, node.normal) * d2);
                const Real c = len > Real(0) ? glm::dot(node.normal, r) / len : Real(0);
                if (c < -node.cone_sin) continue;
            }
            if (open && top + node.child_count <= stack.size()) {
                for (std::uint32_t c = 0; c < node.child_count; ++c) stack[top++] = links_[node.first_link + c];
                continue;
            }
            const Real back = receiving_side<Real, vec>(pr, nr, node.position, Real(two ? 1 : 0));
            const int side = back > Real(0.5) ? 1 : 0;
            const Real f = element_form_factor<Real, vec>(pr, side_normal<Real, vec>(nr, back), ar, node.position, node.normal, node.area);
            if (!(f > Real(0))) continue;
            const vec light = node.unshot * f;
            const double w = channel_sum(glm::abs(light));  // |.|: negative after a re-bake
            if (!(w > 0)) continue;
            incident[side] += light;
            weight[side] += w;
            for (int k = 0; k < samples; ++k)
                if (double(hash_uniform(shot, i, draws * 16 + std::uint64_t(k))) * weight[side] < w) pick[side][k] = j;
            ++draws;
        }
        for (int side = 0; side < int(sides_); ++side) {
            if (!(weight[side] > 0)) continue;
            int seen = 0;
            for (int k = 0; k < samples; ++k) {
                // Down from the disc drawn to one element, by power.
                std::uint32_t j = pick[side][k];
                std::uint64_t level = 0;
                while (group_nodes_[j].child_count > 0) {
                    const group_node& node = group_nodes_[j];
                    double sum = 0;
                    for (std::uint32_t c = 0; c < node.child_count; ++c) sum += double(group_nodes_[links_[node.first_link + c]].power);
                    double u = double(hash_uniform(shot, i, (1ull << 40) + std::uint64_t(side * 16 + k) * 4096 + level++)) * sum;
                    std::uint32_t next = links_[node.first_link + node.child_count - 1];
                    for (std::uint32_t c = 0; c < node.child_count; ++c) {
                        const std::uint32_t child = links_[node.first_link + c];
                        u -= double(group_nodes_[child].power);
                        if (u < 0 && group_nodes_[child].power > Real(0)) {
                            next = child;
                            break;
                        }
                    }
                    j = next;
                }
                if constexpr (casts_from_any_point)
                    seen += vis.visible_from(glm::vec3(group_nodes_[j].position), group_nodes_[j].chart, at.position[i], chart) > 0.5f;
            }
            if (seen == 0) continue;
            received_[side * n + i] = incident[side] * (Real(seen) / Real(samples));
            s.intercepted += glm::dvec3(received_[side * n + i]) * double(ar);
        }
    });
    return total.intercepted;
}

template <shot_visibility Visibility, floating Real>
void progressive_radiosity<Visibility, Real>::shoot_light(const packed_light& l, bool measure_only) {
    const lightmap_atlas& at = atlas_;
    const light_kind kind = l.kind();
    std::vector<shot_frame> frames;
    if (kind == light_kind::directional) frames.push_back({glm::vec3(0.f), l.direction(), true, shot_frame::none});
    else {
        const glm::vec3 axis = kind == light_kind::spot ? l.direction() : glm::vec3(0, 0, 1);
        frames.push_back({l.position(), axis, false, shot_frame::none});
        // A point light, or a spot wider than a hemisphere, needs the other half too.
        if (kind == light_kind::point || l.cos_cone() < 0.f)
            frames.push_back({l.position(), -axis, false, shot_frame::none});
    }
    for (std::size_t h = 0; h < frames.size(); ++h) {
        const shot_frame& frame = frames[h];
        visibility_.begin_shot(frame);
        const Visibility& vis = visibility_;
        const std::size_t count = at.size();
        const int k = options_.light_samples;
        const std::vector<std::uint8_t> whole = k > 1 ? whole_texels(at) : std::vector<std::uint8_t>{};
        const chunk_sums total = distribute([&](std::uint32_t i, chunk_sums& s) {
            const glm::vec3 p = at.position[i], n = at.normal[i];
            if (!frame.parallel) {
                // Each element belongs to exactly one of the hemispheres: z >= 0 of the
                // first, z < 0 of the second (z > 0 along the second's axis).
                if (!(light_hemisphere_side<float, glm::vec3>(p, frame.position, frame.axis, h == 0 ? 0.f : 1.f) > 0.5f))
                    return;
            }
            const auto positive = [](const glm::vec3& x) { return x.x > 0.f || x.y > 0.f || x.z > 0.f; };
            // The side facing the light: the front, or (two-sided) the back.
            glm::vec3 e = light_irradiance(l, p, n);
            std::size_t j = i;
            if (!positive(e) && sides_ == 2) e = light_irradiance(l, p, -n), j = count + i;
            if (!positive(e)) return;
            // At the element's point, or the mean over k x k points of its whole texel.
            glm::vec3 ev = e * vis.visible(p, at.chart[i]);
            if (k > 1 && whole[i]) {
                ev = glm::vec3(0.f);
                for (int a = 0; a < k * k; ++a) {
                    const glm::vec3 q = light_sample_point(at, i, a % k, a / k, k);
                    ev += light_irradiance(l, q, j == i ? n : -n) * vis.visible(q, at.chart[i]);
                }
                ev /= float(k * k);
            }
            if (!positive(ev)) return;
            direct_[j] += vec(ev);
            if (measure_only) return;
            const vec rho = vec(at.albedo[i]);
            const vec gain = rho * vec(ev);
            radiosity_[j] += gain;
            unshot_[j] += gain;
            const glm::dvec3 intercepted = glm::dvec3(ev) * double(at.area[i]);
            s.intercepted += intercepted;
            s.absorbed += (glm::dvec3(1.0) - glm::dvec3(rho)) * intercepted;
        });
        if (measure_only) continue;
        emitted_ += total.intercepted;
        intercepted_ += total.intercepted;
        absorbed_ += total.absorbed;
    }
}

template <shot_visibility Visibility, floating Real>
void progressive_radiosity<Visibility, Real>::regather_lights(const std::vector<vec>& inherited) {
    const auto start = clock::now();
    direct_.assign(inherited.size(), vec(0));
    for (const packed_light& l : lights_) shoot_light(l, true);
    glm::dvec3 added(0), absorbed(0);
    const std::size_t n = atlas_.size();
    for (std::size_t i = 0; i < direct_.size(); ++i) {
        const vec d = direct_[i] - inherited[i];
        if (d == vec(0)) continue;
        const vec rho = vec(atlas_.albedo[i % n]);
        radiosity_[i] += rho * d;
        unshot_[i] += rho * d;
        const glm::dvec3 power = glm::dvec3(d) * double(atlas_.area[i % n]);
        added += power;
        absorbed += (glm::dvec3(1.0) - glm::dvec3(rho)) * power;
    }
    emitted_ += added;
    intercepted_ += added;
    absorbed_ += absorbed;
    timings_.lights_ms += ms_since(start);
}

}  // namespace bounce::cpu
