#pragma once
/// \file emit.hpp
/// Printing a kernel as a GLSL 4.50 function.
///
/// `emit("to_world", to_world<glsl::f32, glsl::vec3>, "d", "n")` reads the parameter and
/// result types from the instantiated function's signature, calls it with symbolic
/// parameters named as given, and prints the expression graph it returns:
/// ```glsl
/// vec3 to_world(vec3 d, vec3 n) {
///     float t0 = n.z >= 0.0 ? 1.0 : -1.0;
///     ...
///     return ...;
/// }
/// ```
/// - Parameters: `f32 vec2 vec3 vec4 boolean` (by value or const reference) print as
///   `float vec2 vec3 vec4 bool`; `std::array<E, N>` of those as `E name[N]`.
/// - Result: one of those types is the return value; `std::array<E, N>` becomes
///   `out E result[N]`, and a `std::tuple`/`std::pair` one `out` parameter per element
///   (`out T result0, ...`), after the inputs. Extra names after the parameter names
///   rename these outputs.
/// - Every node used more than once (by pointer, or structurally equal) becomes a local
///   `tK`, computed once; constants print as the shortest decimal that reads back as the
///   same float (`float_literal`); `select` prints as `c ? a : b`.

#include <bounce/errors.hpp>
#include <bounce/glsl/expr.hpp>

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace bounce::glsl {

/// GLSL literal of a float that reads back as exactly `v`: the shortest round-trip
/// decimal (std::to_chars), with ".0" added to integers ("1.0", "0.1", "1e-07",
/// "-3.4028235e+38"); infinities and NaNs, which have no literal, as
/// `uintBitsToFloat(0x7f800000u)` with their bits.
std::string float_literal(float v);

namespace detail {

/// One thing the function computes: the return value (`target` empty) or an assignment
/// `target = value;` to an out parameter or an element of one.
struct output {
    std::string target;
    node_ptr value;
};

/// Throws parameter_error (naming `what`) unless `name` can name a GLSL variable or
/// function: an identifier, no "__", no "gl_" prefix, not a keyword or a built-in the
/// emitted code calls.
void check_identifier(std::string_view name, const char* what);

/// Prints `return_type name(parameters) { locals; outputs }`. `parameter_names` are
/// checked for clashes with the names of locals.
std::string print_function(const std::string& return_type, const std::string& name,
                           const std::vector<std::string>& parameter_declarations,
                           const std::vector<std::string>& parameter_names, const std::vector<output>& outputs);

// ---- parameter types -------------------------------------------------------------------

template <class T>
struct parameter_traits;

template <expression T>
struct parameter_traits<T> {
    static std::string declaration(const std::string& name) { return std::string(type_name(type_of<T>())) + " " + name; }
    static T make(const std::string& name) { return T(from_node, make_parameter(type_of<T>(), name)); }
};

template <expression E, std::size_t N>
struct parameter_traits<std::array<E, N>> {
    static_assert(N > 0, "GLSL has no empty arrays");
    static std::string declaration(const std::string& name) {
        return std::string(type_name(type_of<E>())) + " " + name + "[" + std::to_string(N) + "]";
    }
    static std::array<E, N> make(const std::string& name) {
        return [&]<std::size_t... I>(std::index_sequence<I...>) {
            return std::array<E, N>{E(from_node, make_parameter(type_of<E>(), name + "[" + std::to_string(I) + "]"))...};
        }(std::make_index_sequence<N>{});
    }
};

// ---- result types ----------------------------------------------------------------------

/// One out parameter: a value or an array of values.
template <class T>
struct out_traits;

template <expression T>
struct out_traits<T> {
    static std::string declaration(const std::string& name) { return "out " + parameter_traits<T>::declaration(name); }
    static void collect(const T& v, const std::string& name, std::vector<output>& outs) { outs.push_back({name, v.node()}); }
};

template <expression E, std::size_t N>
struct out_traits<std::array<E, N>> {
    static std::string declaration(const std::string& name) {
        return "out " + parameter_traits<std::array<E, N>>::declaration(name);
    }
    static void collect(const std::array<E, N>& v, const std::string& name, std::vector<output>& outs) {
        for (std::size_t i = 0; i < N; ++i) outs.push_back({name + "[" + std::to_string(i) + "]", v[i].node()});
    }
};

template <class R>
struct result_traits;

/// A single value: the function's return value.
template <expression R>
struct result_traits<R> {
    static constexpr std::size_t outs = 0;
    static std::string return_type() { return type_name(type_of<R>()); }
    static std::vector<std::string> default_names() { return {}; }
    static std::vector<std::string> declarations(const std::vector<std::string>&) { return {}; }
    static void collect(const R& r, const std::vector<std::string>&, std::vector<output>& o) { o.push_back({"", r.node()}); }
};

/// An array: one out parameter.
template <expression E, std::size_t N>
struct result_traits<std::array<E, N>> {
    using out = out_traits<std::array<E, N>>;
    static constexpr std::size_t outs = 1;
    static std::string return_type() { return "void"; }
    static std::vector<std::string> default_names() { return {"result"}; }
    static std::vector<std::string> declarations(const std::vector<std::string>& n) { return {out::declaration(n[0])}; }
    static void collect(const std::array<E, N>& r, const std::vector<std::string>& n, std::vector<output>& o) {
        out::collect(r, n[0], o);
    }
};

/// A tuple (or pair) of values and arrays: one out parameter per element.
template <template <class...> class Tuple, class... E>
    requires(std::same_as<Tuple<E...>, std::tuple<E...>> || std::same_as<Tuple<E...>, std::pair<E...>>)
struct result_traits<Tuple<E...>> {
    static constexpr std::size_t outs = sizeof...(E);
    static std::string return_type() { return "void"; }
    static std::vector<std::string> default_names() {
        std::vector<std::string> n;
        for (std::size_t i = 0; i < outs; ++i) n.push_back("result" + std::to_string(i));
        return n;
    }
    static std::vector<std::string> declarations(const std::vector<std::string>& n) {
        return [&]<std::size_t... I>(std::index_sequence<I...>) {
            return std::vector<std::string>{out_traits<E>::declaration(n[I])...};
        }(std::index_sequence_for<E...>{});
    }
    static void collect(const Tuple<E...>& r, const std::vector<std::string>& n, std::vector<output>& o) {
        [&]<std::size_t... I>(std::index_sequence<I...>) {
            (out_traits<E>::collect(std::get<I>(r), n[I], o), ...);
        }(std::index_sequence_for<E...>{});
    }
};

// ---- the signature of what is emitted --------------------------------------------------

template <class F>
struct signature : signature<decltype(&F::operator())> {};
template <class R, class... A>
struct signature<R (*)(A...)> {
    using result = std::remove_cvref_t<R>;
    using arguments = std::tuple<std::remove_cvref_t<A>...>;
};
template <class R, class C, class... A>
struct signature<R (C::*)(A...) const> : signature<R (*)(A...)> {};
template <class R, class C, class... A>
struct signature<R (C::*)(A...)> : signature<R (*)(A...)> {};

template <class F>
using signature_of = signature<std::decay_t<F>>;

}  // namespace detail

/// Prints the GLSL 4.50 function `name` computing `fn`, a function (e.g. a kernel
/// template instantiated on glsl types, `to_world<glsl::f32, glsl::vec3>`) or a lambda
/// with fixed parameter types. `names` are the GLSL parameter names, one per parameter of
/// `fn`, optionally followed by one name per out parameter of the result (defaults:
/// "result" for an array, "result0", "result1", ... for a tuple).
/// Throws parameter_error when a name is not a usable GLSL identifier or is repeated.
template <class F, class... Names>
std::string emit(const std::string& name, F&& fn, const Names&... names) {
    using sig = detail::signature_of<F>;
    using args = typename sig::arguments;
    using result = detail::result_traits<typename sig::result>;
    constexpr std::size_t arity = std::tuple_size_v<args>;
    static_assert(sizeof...(Names) == arity || sizeof...(Names) == arity + result::outs,
                  "glsl::emit: give one name per parameter, then optionally one per out parameter");

    detail::check_identifier(name, "name");
    const std::vector<std::string> all{std::string(names)...};
    std::vector<std::string> out_names = result::default_names();
    for (std::size_t i = arity; i < all.size(); ++i) out_names[i - arity] = all[i];

    std::vector<std::string> declarations, parameter_names(all.begin(), all.begin() + arity);
    for (const auto& n : out_names) parameter_names.push_back(n);
    for (const auto& n : parameter_names) detail::check_identifier(n, "names");
    for (std::size_t i = 0; i < parameter_names.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (parameter_names[i] == parameter_names[j])
                throw parameter_error("names", "'" + parameter_names[i] + "' is used twice");

    auto symbolic = [&]<std::size_t... I>(std::index_sequence<I...>) {
        (declarations.push_back(detail::parameter_traits<std::tuple_element_t<I, args>>::declaration(all[I])), ...);
        return args{detail::parameter_traits<std::tuple_element_t<I, args>>::make(all[I])...};
    }(std::make_index_sequence<arity>{});
    for (auto& d : result::declarations(out_names)) declarations.push_back(std::move(d));

    const auto value = std::apply(fn, symbolic);
    std::vector<detail::output> outputs;
    result::collect(value, out_names, outputs);
    return detail::print_function(result::return_type(), name, declarations, parameter_names, outputs);
}

/// Several emitted functions in one source, each once: a pass collects the functions
/// its shaders call, in the order added, and pastes `source()` before its `main`.
class function_set {
public:
    /// Emits `fn` as `name` (see `emit`) and adds it as `add_source` does.
    template <class F, class... Names>
    function_set& add(const std::string& name, F&& fn, const Names&... names) {
        return add_source(name, emit(name, std::forward<F>(fn), names...));
    }
    /// Adds a printed function. The same name twice is kept once if the text is the same,
    /// and throws parameter_error if it differs (two different functions, one name).
    function_set& add_source(const std::string& name, std::string text);
    bool contains(std::string_view name) const noexcept;
    /// The functions, in the order added, separated by blank lines.
    std::string source() const;

private:
    std::vector<std::pair<std::string, std::string>> functions_;
};

}  // namespace bounce::glsl
