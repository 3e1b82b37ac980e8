#pragma once
/// \file expr.hpp
/// GLSL expression types: `f32`, `vec2`, `vec3`, `vec4`, `boolean`.
///
/// A kernel of `include/bounce/` instantiated on these types does not compute: every
/// operator and vocabulary function adds a node to an expression graph (nodes are shared,
/// so a value used twice is one node), and `glsl::emit` (emit.hpp) prints the graph as a
/// GLSL 4.50 function. The free functions carry GLSL's names and are found by
/// argument-dependent lookup from the kernels, which call them unqualified.
///
/// Constants are single precision (GLSL `float`): `f32(0.1)` holds `float(0.1)`, the same
/// value the CPU `float` instantiation uses, and arithmetic on two constants is folded in
/// `float`, exactly as the CPU computes it.

#include <array>
#include <concepts>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace bounce::glsl {

/// The GLSL types an expression can have.
enum class type : std::uint8_t { f32, vec2, vec3, vec4, boolean };

/// GLSL spelling of a type: "float", "vec2", "vec3", "vec4", "bool".
constexpr const char* type_name(type t) noexcept {
    switch (t) {
        case type::f32: return "float";
        case type::vec2: return "vec2";
        case type::vec3: return "vec3";
        case type::vec4: return "vec4";
        case type::boolean: return "bool";
    }
    return "?";
}
/// Number of float components: 1 for float and bool, N for vecN.
constexpr int component_count(type t) noexcept {
    return t == type::vec2 ? 2 : t == type::vec3 ? 3 : t == type::vec4 ? 4 : 1;
}

namespace detail {

/// What a node computes.
enum class op : std::uint8_t {
    constant,   ///< `value` (bool: 0 or 1)
    parameter,  ///< a function parameter or an element of one (`name`, e.g. "n" or "c[3]")
    swizzle,    ///< component `index` of args[0]
    construct,  ///< vecN(args...)
    negate, logical_not,
    add, subtract, multiply, divide,
    less, greater, less_equal, greater_equal, equal, not_equal,
    logical_and, logical_or,
    call,    ///< GLSL built-in `name`(args...)
    select,  ///< args[0] ? args[1] : args[2]
};

struct node;
using node_ptr = std::shared_ptr<const node>;

/// One vertex of the expression graph. Immutable once built, shared by every user.
struct node {
    glsl::type type;
    detail::op op;
    float value = 0.f;  ///< constant value
    int index = 0;      ///< swizzle component 0..3
    std::string name;   ///< parameter name or built-in function name
    std::vector<node_ptr> args;
};

node_ptr make_constant(float value);
node_ptr make_bool_constant(bool value);
node_ptr make_parameter(glsl::type t, std::string name);
/// Component `i` of a vector; of a `construct` node it is the constructing argument itself.
node_ptr make_swizzle(const node_ptr& v, int i);
/// vecN(args): N scalars, one scalar (splat), or a vector and scalars adding up to N.
node_ptr make_construct(glsl::type t, std::vector<node_ptr> args);
node_ptr make_unary(op o, const node_ptr& a);
/// Binary operator with result type `t`; folds two float constants in `float` arithmetic.
node_ptr make_binary(op o, glsl::type t, const node_ptr& a, const node_ptr& b);
node_ptr make_call(glsl::type t, std::string function, std::vector<node_ptr> args);
/// c ? a : b; a constant condition picks its operand.
node_ptr make_select(const node_ptr& c, const node_ptr& a, const node_ptr& b);

/// Tag for constructing an expression from an existing node.
struct from_node_t {
    explicit from_node_t() = default;
};
inline constexpr from_node_t from_node{};

}  // namespace detail

/// A GLSL `float` expression. Constructible from a double (a constant) like a number.
class f32 {
public:
    /// The constant 0.
    f32() : f32(0.0) {}
    /// The constant `float(v)`.
    explicit f32(double v) : node_(detail::make_constant(static_cast<float>(v))) {}
    f32(detail::from_node_t, detail::node_ptr n) : node_(std::move(n)) {}
    const detail::node_ptr& node() const noexcept { return node_; }

private:
    detail::node_ptr node_;
};

/// A GLSL `bool` expression: the result of a comparison, an operand of `select`.
class boolean {
public:
    /// The constant `false`.
    boolean() : boolean(false) {}
    explicit boolean(bool v) : node_(detail::make_bool_constant(v)) {}
    boolean(detail::from_node_t, detail::node_ptr n) : node_(std::move(n)) {}
    const detail::node_ptr& node() const noexcept { return node_; }

private:
    detail::node_ptr node_;
};

template <int N>
struct vec_components;
template <>
struct vec_components<2> {
    explicit vec_components(const std::array<detail::node_ptr, 2>& c)
        : x(detail::from_node, c[0]), y(detail::from_node, c[1]) {}
    f32 x, y;
};
template <>
struct vec_components<3> {
    explicit vec_components(const std::array<detail::node_ptr, 3>& c)
        : x(detail::from_node, c[0]), y(detail::from_node, c[1]), z(detail::from_node, c[2]) {}
    f32 x, y, z;
};
template <>
struct vec_components<4> {
    explicit vec_components(const std::array<detail::node_ptr, 4>& c)
        : x(detail::from_node, c[0]), y(detail::from_node, c[1]), z(detail::from_node, c[2]), w(detail::from_node, c[3]) {}
    f32 x, y, z, w;
};

/// A GLSL `vecN` expression. The components `.x .y .z .w` are readable (and assignable)
/// members: a component of a vector built from scalars is that scalar itself, otherwise a
/// swizzle node, so `vec3(a, b, c).y` prints as `b`.
template <int N>
class vec : public vec_components<N> {
    static_assert(N >= 2 && N <= 4);

public:
    static constexpr glsl::type type_id = N == 2 ? glsl::type::vec2 : N == 3 ? glsl::type::vec3 : glsl::type::vec4;

    /// The zero vector.
    vec() : vec(f32(0.0)) {}
    /// All components equal to `s` (GLSL `vecN(s)`).
    explicit vec(const f32& s) : vec(detail::from_node, detail::make_construct(type_id, {s.node()})) {}
    vec(const f32& a, const f32& b)
        requires(N == 2)
        : vec(detail::from_node, detail::make_construct(type_id, {a.node(), b.node()})) {}
    vec(const f32& a, const f32& b, const f32& c)
        requires(N == 3)
        : vec(detail::from_node, detail::make_construct(type_id, {a.node(), b.node(), c.node()})) {}
    vec(const f32& a, const f32& b, const f32& c, const f32& d)
        requires(N == 4)
        : vec(detail::from_node, detail::make_construct(type_id, {a.node(), b.node(), c.node(), d.node()})) {}
    /// vec3(xy, z).
    vec(const vec<2>& xy, const f32& z)
        requires(N == 3)
        : vec(detail::from_node, detail::make_construct(type_id, {xy.node(), z.node()})) {}
    /// vec4(xyz, w).
    vec(const vec<3>& xyz, const f32& w)
        requires(N == 4)
        : vec(detail::from_node, detail::make_construct(type_id, {xyz.node(), w.node()})) {}

    vec(detail::from_node_t, detail::node_ptr n) : vec(n, split(n)) {}
    /// The vector's node; if a component was assigned since, a new `vecN(x, y, ...)`.
    detail::node_ptr node() const {
        bool same = true;
        for (int i = 0; i < N; ++i) same = same && member(i).node() == built_[std::size_t(i)];
        if (same) return node_;
        std::vector<detail::node_ptr> components;
        for (int i = 0; i < N; ++i) components.push_back(member(i).node());
        return detail::make_construct(type_id, std::move(components));
    }

    /// Component i (0 = x), as in GLSL `v[i]` with a constant index.
    f32 operator[](int i) const { return member(i); }

    static constexpr int length() noexcept { return N; }

private:
    using parts = std::array<detail::node_ptr, std::size_t(N)>;
    vec(detail::node_ptr n, const parts& p) : vec_components<N>(p), node_(std::move(n)), built_(p) {}
    static parts split(const detail::node_ptr& n) {
        parts p;
        for (int i = 0; i < N; ++i) p[std::size_t(i)] = detail::make_swizzle(n, i);
        return p;
    }

    f32& member(int i) {
        if constexpr (N == 2) return i == 0 ? this->x : this->y;
        else if constexpr (N == 3) return i == 0 ? this->x : i == 1 ? this->y : this->z;
        else return i == 0 ? this->x : i == 1 ? this->y : i == 2 ? this->z : this->w;
    }
    const f32& member(int i) const { return const_cast<vec*>(this)->member(i); }

    detail::node_ptr node_;
    parts built_;  // the component nodes node_ was split into, to notice assignments
};

using vec2 = vec<2>;
using vec3 = vec<3>;
using vec4 = vec<4>;

/// One of the expression types a value can have.
template <class T>
concept expression = std::same_as<T, f32> || std::same_as<T, boolean> || std::same_as<T, vec2> ||
                     std::same_as<T, vec3> || std::same_as<T, vec4>;
/// GLSL genType: float or vecN (what the component-wise built-ins accept).
template <class T>
concept gen_type = std::same_as<T, f32> || std::same_as<T, vec2> || std::same_as<T, vec3> || std::same_as<T, vec4>;
/// vecN only.
template <class T>
concept vector_type = std::same_as<T, vec2> || std::same_as<T, vec3> || std::same_as<T, vec4>;

/// The GLSL type of an expression type.
template <expression T>
constexpr glsl::type type_of() noexcept {
    if constexpr (std::same_as<T, f32>) return type::f32;
    else if constexpr (std::same_as<T, boolean>) return type::boolean;
    else return T::type_id;
}

namespace detail {
template <expression T>
T wrap(node_ptr n) {
    return T(from_node, std::move(n));
}
template <gen_type T>
T unary_fn(const char* name, const T& a) {
    return wrap<T>(make_call(type_of<T>(), name, {a.node()}));
}
template <gen_type T, class A, class B>
T binary_fn(const char* name, const A& a, const B& b) {
    return wrap<T>(make_call(type_of<T>(), name, {a.node(), b.node()}));
}
}  // namespace detail

// ---- arithmetic -------------------------------------------------------------------------
// Same-type operands (component-wise for vectors), and a vector with a scalar either side,
// as GLSL allows.

template <gen_type T>
T operator+(const T& a, const T& b) { return detail::wrap<T>(detail::make_binary(detail::op::add, type_of<T>(), a.node(), b.node())); }
template <gen_type T>
T operator-(const T& a, const T& b) { return detail::wrap<T>(detail::make_binary(detail::op::subtract, type_of<T>(), a.node(), b.node())); }
template <gen_type T>
T operator*(const T& a, const T& b) { return detail::wrap<T>(detail::make_binary(detail::op::multiply, type_of<T>(), a.node(), b.node())); }
template <gen_type T>
T operator/(const T& a, const T& b) { return detail::wrap<T>(detail::make_binary(detail::op::divide, type_of<T>(), a.node(), b.node())); }
template <gen_type T>
T operator-(const T& a) { return detail::wrap<T>(detail::make_unary(detail::op::negate, a.node())); }
template <gen_type T>
T operator+(const T& a) { return a; }

template <vector_type V>
V operator+(const V& a, const f32& s) { return detail::wrap<V>(detail::make_binary(detail::op::add, type_of<V>(), a.node(), s.node())); }
template <vector_type V>
V operator+(const f32& s, const V& a) { return detail::wrap<V>(detail::make_binary(detail::op::add, type_of<V>(), s.node(), a.node())); }
template <vector_type V>
V operator-(const V& a, const f32& s) { return detail::wrap<V>(detail::make_binary(detail::op::subtract, type_of<V>(), a.node(), s.node())); }
template <vector_type V>
V operator-(const f32& s, const V& a) { return detail::wrap<V>(detail::make_binary(detail::op::subtract, type_of<V>(), s.node(), a.node())); }
template <vector_type V>
V operator*(const V& a, const f32& s) { return detail::wrap<V>(detail::make_binary(detail::op::multiply, type_of<V>(), a.node(), s.node())); }
template <vector_type V>
V operator*(const f32& s, const V& a) { return detail::wrap<V>(detail::make_binary(detail::op::multiply, type_of<V>(), s.node(), a.node())); }
template <vector_type V>
V operator/(const V& a, const f32& s) { return detail::wrap<V>(detail::make_binary(detail::op::divide, type_of<V>(), a.node(), s.node())); }
template <vector_type V>
V operator/(const f32& s, const V& a) { return detail::wrap<V>(detail::make_binary(detail::op::divide, type_of<V>(), s.node(), a.node())); }

template <gen_type T>
T& operator+=(T& a, const auto& b) { return a = a + b; }
template <gen_type T>
T& operator-=(T& a, const auto& b) { return a = a - b; }
template <gen_type T>
T& operator*=(T& a, const auto& b) { return a = a * b; }
template <gen_type T>
T& operator/=(T& a, const auto& b) { return a = a / b; }

// ---- comparisons and logic (scalars) ----------------------------------------------------

inline boolean operator<(const f32& a, const f32& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::less, type::boolean, a.node(), b.node())); }
inline boolean operator>(const f32& a, const f32& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::greater, type::boolean, a.node(), b.node())); }
inline boolean operator<=(const f32& a, const f32& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::less_equal, type::boolean, a.node(), b.node())); }
inline boolean operator>=(const f32& a, const f32& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::greater_equal, type::boolean, a.node(), b.node())); }
inline boolean operator==(const f32& a, const f32& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::equal, type::boolean, a.node(), b.node())); }
inline boolean operator!=(const f32& a, const f32& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::not_equal, type::boolean, a.node(), b.node())); }
inline boolean operator==(const boolean& a, const boolean& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::equal, type::boolean, a.node(), b.node())); }
inline boolean operator!=(const boolean& a, const boolean& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::not_equal, type::boolean, a.node(), b.node())); }
/// Logical and. Both operands are already built, so nothing is short-circuited.
inline boolean operator&&(const boolean& a, const boolean& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::logical_and, type::boolean, a.node(), b.node())); }
/// Logical or. Both operands are already built, so nothing is short-circuited.
inline boolean operator||(const boolean& a, const boolean& b) { return detail::wrap<boolean>(detail::make_binary(detail::op::logical_or, type::boolean, a.node(), b.node())); }
inline boolean operator!(const boolean& a) { return detail::wrap<boolean>(detail::make_unary(detail::op::logical_not, a.node())); }

// ---- the kernel vocabulary (GLSL built-ins) ---------------------------------------------

/// `select(c, a, b)`: `a` where `c` holds, else `b`; printed as the ternary `c ? a : b`.
template <expression T>
T select(const boolean& c, const T& a, const T& b) { return detail::wrap<T>(detail::make_select(c.node(), a.node(), b.node())); }

template <gen_type T> T sqrt(const T& x) { return detail::unary_fn("sqrt", x); }
/// 1 / sqrt(x).
template <gen_type T> T inversesqrt(const T& x) { return detail::unary_fn("inversesqrt", x); }
template <gen_type T> T abs(const T& x) { return detail::unary_fn("abs", x); }
template <gen_type T> T exp(const T& x) { return detail::unary_fn("exp", x); }
template <gen_type T> T log(const T& x) { return detail::unary_fn("log", x); }
template <gen_type T> T sin(const T& x) { return detail::unary_fn("sin", x); }
template <gen_type T> T cos(const T& x) { return detail::unary_fn("cos", x); }
template <gen_type T> T floor(const T& x) { return detail::unary_fn("floor", x); }
template <gen_type T> T normalize(const T& x) { return detail::unary_fn("normalize", x); }
template <gen_type T> T pow(const T& x, const T& y) { return detail::binary_fn<T>("pow", x, y); }
/// atan(y, x): the angle of (x, y) in [-pi, pi], as C's atan2.
template <gen_type T> T atan(const T& y, const T& x) { return detail::binary_fn<T>("atan", y, x); }
template <gen_type T> T min(const T& a, const T& b) { return detail::binary_fn<T>("min", a, b); }
template <gen_type T> T max(const T& a, const T& b) { return detail::binary_fn<T>("max", a, b); }
template <vector_type V> V min(const V& a, const f32& b) { return detail::binary_fn<V>("min", a, b); }
template <vector_type V> V max(const V& a, const f32& b) { return detail::binary_fn<V>("max", a, b); }
/// min(max(x, lo), hi), the CPU definition; GLSL's `clamp` is undefined for lo > hi.
template <gen_type T> T clamp(const T& x, const T& lo, const T& hi) { return min(max(x, lo), hi); }
template <vector_type V> V clamp(const V& x, const f32& lo, const f32& hi) { return min(max(x, lo), hi); }
/// a (1 - t) + b t.
template <gen_type T> T mix(const T& a, const T& b, const T& t) {
    return detail::wrap<T>(detail::make_call(type_of<T>(), "mix", {a.node(), b.node(), t.node()}));
}
template <vector_type V> V mix(const V& a, const V& b, const f32& t) {
    return detail::wrap<V>(detail::make_call(type_of<V>(), "mix", {a.node(), b.node(), t.node()}));
}
template <gen_type T> f32 dot(const T& a, const T& b) { return detail::wrap<f32>(detail::make_call(type::f32, "dot", {a.node(), b.node()})); }
template <gen_type T> f32 length(const T& a) { return detail::wrap<f32>(detail::make_call(type::f32, "length", {a.node()})); }
inline vec3 cross(const vec3& a, const vec3& b) { return detail::binary_fn<vec3>("cross", a, b); }

}  // namespace bounce::glsl
