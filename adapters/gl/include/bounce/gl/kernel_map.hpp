#pragma once
/// \file kernel_map.hpp
/// Evaluating a kernel on the GPU over a batch of inputs: the emitted function wrapped in a
/// compute shader that reads each element's arguments from one storage buffer and writes
/// its results to another. This is how the tests compare every kernel's GLSL with its CPU
/// instantiation, and a quick way to run a kernel where a pass would be overkill.
///
/// ```cpp
/// std::vector<std::tuple<glm::vec3, glm::vec3>> in = ...;          // (d, n) pairs
/// auto out = gl::map_kernel(to_world<glsl::f32, glsl::vec3>, in);  // std::vector<glm::vec3>
/// ```

#include <bounce/gl/objects.hpp>
#include <bounce/glsl/emit.hpp>

#include <array>
#include <cstring>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::gl {

namespace detail {

/// How a value of GLSL type G travels through the float storage buffers: its CPU type
/// (`host`), its size in floats, packing on the CPU, loading and storing in GLSL.
template <class G>
struct lane;

template <glsl::expression G>
struct lane<G> {
    static constexpr int n = glsl::component_count(glsl::type_of<G>());
    using host = std::conditional_t<std::same_as<G, glsl::boolean>, bool,
                                    std::conditional_t<n == 1, float, glm::vec<n, float>>>;
    static constexpr std::size_t floats = std::size_t(n);

    static void pack(const host& v, float* p) {
        if constexpr (std::same_as<host, bool>) p[0] = v ? 1.f : 0.f;
        else if constexpr (n == 1) p[0] = v;
        else
            for (int i = 0; i < n; ++i) p[i] = v[i];
    }
    static void unpack(const float* p, host& v) {
        if constexpr (std::same_as<host, bool>) v = p[0] != 0.f;
        else if constexpr (n == 1) v = p[0];
        else
            for (int i = 0; i < n; ++i) v[i] = p[i];
    }
    // GLSL expression reading the value at float offset `at` of in_data[in_base + ...].
    static std::string load(std::size_t at) {
        const auto f = [](std::size_t k) { return "in_data[in_base + " + std::to_string(k) + "u]"; };
        if constexpr (std::same_as<G, glsl::boolean>) return f(at) + " != 0.0";
        else if constexpr (n == 1) return f(at);
        else {
            std::string s = std::string(glsl::type_name(glsl::type_of<G>())) + "(";
            for (int i = 0; i < n; ++i) s += (i ? ", " : "") + f(at + std::size_t(i));
            return s + ")";
        }
    }
    static std::string declare(const std::string& name) { return std::string(glsl::type_name(glsl::type_of<G>())) + " " + name; }
    static std::string load_statements(const std::string& name, std::size_t at) {
        return "    " + declare(name) + " = " + load(at) + ";\n";
    }
    static std::string store_statements(const std::string& expr, std::size_t at) {
        const auto f = [](std::size_t k) { return "    out_data[out_base + " + std::to_string(k) + "u] = "; };
        if constexpr (std::same_as<G, glsl::boolean>) return f(at) + expr + " ? 1.0 : 0.0;\n";
        else if constexpr (n == 1) return f(at) + expr + ";\n";
        else {
            std::string s;
            for (int i = 0; i < n; ++i) s += f(at + std::size_t(i)) + expr + "." + "xyzw"[i] + ";\n";
            return s;
        }
    }
};

template <glsl::expression E, std::size_t N>
struct lane<std::array<E, N>> {
    using element = lane<E>;
    using host = std::array<typename element::host, N>;
    static constexpr std::size_t floats = N * element::floats;

    static void pack(const host& v, float* p) {
        for (std::size_t i = 0; i < N; ++i) element::pack(v[i], p + i * element::floats);
    }
    static void unpack(const float* p, host& v) {
        for (std::size_t i = 0; i < N; ++i) element::unpack(p + i * element::floats, v[i]);
    }
    static std::string declare(const std::string& name) { return element::declare(name) + "[" + std::to_string(N) + "]"; }
    static std::string load_statements(const std::string& name, std::size_t at) {
        std::string s = "    " + declare(name) + ";\n";
        for (std::size_t i = 0; i < N; ++i)
            s += "    " + name + "[" + std::to_string(i) + "] = " + element::load(at + i * element::floats) + ";\n";
        return s;
    }
    static std::string store_statements(const std::string& expr, std::size_t at) {
        std::string s;
        for (std::size_t i = 0; i < N; ++i)
            s += element::store_statements(expr + "[" + std::to_string(i) + "]", at + i * element::floats);
        return s;
    }
};

/// The results: a value or an array is one out lane; a tuple or pair, one per element.
template <class R>
struct result_lanes {
    using host = typename lane<R>::host;
    static constexpr std::size_t floats = lane<R>::floats;
    static constexpr bool returned = glsl::expression<R>;  // a return value, not an out parameter
    static std::vector<std::string> names() { return {"r0"}; }
    static std::string declarations() { return returned ? "" : "    " + lane<R>::declare("r0") + ";\n"; }
    static std::string stores() { return lane<R>::store_statements("r0", 0); }
    static void unpack(const float* p, host& v) { lane<R>::unpack(p, v); }
};

template <template <class...> class Tuple, class... E>
    requires(std::same_as<Tuple<E...>, std::tuple<E...>> || std::same_as<Tuple<E...>, std::pair<E...>>)
struct result_lanes<Tuple<E...>> {
    using host = Tuple<typename lane<E>::host...>;
    static constexpr std::size_t floats = (lane<E>::floats + ...);
    static constexpr bool returned = false;
    static std::vector<std::string> names() {
        std::vector<std::string> n;
        for (std::size_t i = 0; i < sizeof...(E); ++i) n.push_back(std::string("r") + std::to_string(i));
        return n;
    }
    static std::string declarations() {
        return [&]<std::size_t... I>(std::index_sequence<I...>) {
            return ((std::string("    ") + lane<E>::declare(std::string("r") + std::to_string(I)) + ";\n") + ...);
        }(std::index_sequence_for<E...>{});
    }
    static std::string stores() {
        std::string s;
        std::size_t at = 0;
        [&]<std::size_t... I>(std::index_sequence<I...>) {
            ((s += lane<E>::store_statements(std::string("r") + std::to_string(I), at), at += lane<E>::floats), ...);
        }(std::index_sequence_for<E...>{});
        return s;
    }
    static void unpack(const float* p, host& v) {
        [&]<std::size_t... I>(std::index_sequence<I...>) {
            std::size_t at = 0;
            ((lane<E>::unpack(p + at, std::get<I>(v)), at += lane<E>::floats), ...);
        }(std::index_sequence_for<E...>{});
    }
};

template <class Args>
struct argument_lanes;
template <class... A>
struct argument_lanes<std::tuple<A...>> {
    using host = std::tuple<typename lane<A>::host...>;
    static constexpr std::size_t floats = (std::size_t(0) + ... + lane<A>::floats);
};

/// Runs the compute program `source` (local size 64; reads `in_data`, binding 0, writes
/// `out_data`, binding 1; uniforms `first` at location 0 and `count` at 1) over `count`
/// elements and returns out_data. Restores the program and storage bindings it changes.
std::vector<float> run_map(const std::string& source, std::span<const float> inputs, std::size_t count,
                           std::size_t out_floats_per_element);

}  // namespace detail

/// The CPU types `map_kernel` takes and returns for a kernel `F` on glsl types: f32 ->
/// float, vecN -> glm::vecN, boolean -> bool, std::array / std::tuple / std::pair of those.
template <class F>
using kernel_arguments = typename detail::argument_lanes<typename glsl::detail::signature_of<F>::arguments>::host;
template <class F>
using kernel_result = typename detail::result_lanes<typename glsl::detail::signature_of<F>::result>::host;

/// Which API a compute shader of `map_kernel_source` is written for. Both are GLSL 4.50 with
/// the same body; they differ in how the range reaches the shader and how buffers are named:
/// - opengl: `first` and `count` are uniforms at locations 0 and 1; buffers at bindings 0, 1;
/// - vulkan: `first` and `count` are push constants (two uints at offsets 0 and 4); buffers
///   at set 0, bindings 0 (inputs) and 1 (outputs). glslang compiles it to SPIR-V
///   (`--target-env vulkan1.2`); tests/spirv validates every kernel's with spirv-val.
enum class compute_target { opengl, vulkan };

/// The compute shader `map_kernel` runs for `fn`: plumbing only (loads, one call of the
/// emitted function, stores) around `glsl::emit("bounce_kernel", fn, ...)`.
template <class F>
std::string map_kernel_source(F&& fn, compute_target target = compute_target::opengl) {
    using sig = glsl::detail::signature_of<F>;
    using args = typename sig::arguments;
    using results = detail::result_lanes<typename sig::result>;
    constexpr std::size_t arity = std::tuple_size_v<args>;
    constexpr std::size_t in_floats = detail::argument_lanes<args>::floats;

    std::string loads, call_args;
    std::size_t at = 0;
    [&]<std::size_t... I>(std::index_sequence<I...>) {
        ((loads += detail::lane<std::tuple_element_t<I, args>>::load_statements(std::string("a") + std::to_string(I), at),
          at += detail::lane<std::tuple_element_t<I, args>>::floats,
          call_args.append(I ? ", a" : "a").append(std::to_string(I))),
         ...);
    }(std::make_index_sequence<arity>{});

    std::string function;
    std::string call;
    if constexpr (results::returned) {
        function = [&]<std::size_t... I>(std::index_sequence<I...>) {
            return glsl::emit("bounce_kernel", fn, (std::string("a") + std::to_string(I))...);
        }(std::make_index_sequence<arity>{});
        using R = typename sig::result;
        call = "    " + detail::lane<R>::declare("r0") + " = bounce_kernel(" + call_args + ");\n";
    } else {
        const auto outs = results::names();
        function = [&]<std::size_t... I, std::size_t... O>(std::index_sequence<I...>, std::index_sequence<O...>) {
            return glsl::emit("bounce_kernel", fn, (std::string("a") + std::to_string(I))..., outs[O]...);
        }(std::make_index_sequence<arity>{}, std::make_index_sequence<glsl::detail::result_traits<typename sig::result>::outs>{});
        for (const auto& o : outs) call_args += (call_args.empty() ? "" : ", ") + o;
        call = results::declarations() + "    bounce_kernel(" + call_args + ");\n";
    }
    const bool vulkan = target == compute_target::vulkan;
    const std::string set = vulkan ? "set = 0, " : "";
    return "#version 450 core\n"
           "layout(local_size_x = 64) in;\n"
           "layout(std430, " + set + "binding = 0) readonly buffer bounce_inputs { float in_data[]; };\n"
           "layout(std430, " + set + "binding = 1) writeonly buffer bounce_outputs { float out_data[]; };\n" +
           (vulkan ? "layout(push_constant) uniform bounce_range { uint first; uint count; };\n\n"
                   : "layout(location = 0) uniform uint first;\n"
                     "layout(location = 1) uniform uint count;\n\n") +
           function +
           "\nvoid main() {\n"
           "    uint i = first + gl_GlobalInvocationID.x;\n"
           "    if (i >= count) return;\n"
           "    uint in_base = i * " + std::to_string(in_floats) + "u;\n"
           "    uint out_base = i * " + std::to_string(results::floats) + "u;\n" +
           loads + call + results::stores() + "}\n";
}

/// Evaluates `fn` (a kernel instantiated on glsl types, or a lambda with glsl parameter
/// types) on the GPU for every element of `inputs`, in the context current on this thread,
/// and returns the results in order. Restores the program and the storage-buffer bindings
/// 0 and 1 it uses. Throws shader_error if the emitted code does not compile, gl_error on
/// a GL failure.
template <class F>
std::vector<kernel_result<F>> map_kernel(F&& fn, std::span<const kernel_arguments<F>> inputs) {
    using sig = glsl::detail::signature_of<F>;
    using args = typename sig::arguments;
    using results = detail::result_lanes<typename sig::result>;
    constexpr std::size_t in_floats = detail::argument_lanes<args>::floats;
    std::vector<kernel_result<F>> out(inputs.size());
    if (inputs.empty()) return out;

    std::vector<float> packed(inputs.size() * std::max<std::size_t>(in_floats, 1));
    for (std::size_t e = 0; e < inputs.size(); ++e) {
        std::size_t at = e * in_floats;
        [&]<std::size_t... I>(std::index_sequence<I...>) {
            ((detail::lane<std::tuple_element_t<I, args>>::pack(std::get<I>(inputs[e]), packed.data() + at),
              at += detail::lane<std::tuple_element_t<I, args>>::floats),
             ...);
        }(std::make_index_sequence<std::tuple_size_v<args>>{});
    }
    const auto raw = detail::run_map(map_kernel_source(fn), packed, inputs.size(), results::floats);
    for (std::size_t e = 0; e < inputs.size(); ++e) results::unpack(raw.data() + e * results::floats, out[e]);
    return out;
}

/// `map_kernel` over a vector of argument tuples.
template <class F>
std::vector<kernel_result<F>> map_kernel(F&& fn, const std::vector<kernel_arguments<F>>& inputs) {
    return map_kernel(std::forward<F>(fn), std::span<const kernel_arguments<F>>(inputs));
}

}  // namespace bounce::gl
