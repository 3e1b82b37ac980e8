// Building the expression graph: node constructors with the few simplifications that
// cannot change a result (float constant folding, components of a constructed vector,
// constant conditions).
#include <bounce/errors.hpp>
#include <bounce/glsl/expr.hpp>


namespace bounce::glsl {

namespace detail {
namespace {

std::shared_ptr<node> make(type t, op o, std::vector<node_ptr> args = {}, std::string name = {}) {
    auto n = std::make_shared<node>();
    n->type = t;
    n->op = o;
    n->name = std::move(name);
    n->args = std::move(args);
    return n;
}

bool is_constant(const node_ptr& n, type t) { return n->op == op::constant && n->type == t; }

}  // namespace

node_ptr make_constant(float value) {
    auto n = std::make_shared<node>();
    n->type = type::f32;
    n->op = op::constant;
    n->value = value;
    return n;
}

node_ptr make_bool_constant(bool value) {
    auto n = std::make_shared<node>();
    n->type = type::boolean;
    n->op = op::constant;
    n->value = value ? 1.f : 0.f;
    return n;
}

node_ptr make_parameter(type t, std::string name) { return make(t, op::parameter, {}, std::move(name)); }

node_ptr make_swizzle(const node_ptr& v, int i) {
    require(component_count(v->type) > i && i >= 0 && v->type != type::boolean, "component", "outside the vector");
    if (v->op == op::construct) {
        // vecN(s) has s everywhere; vecN(a, b, ...) has its arguments in order, each
        // covering as many components as it has.
        if (v->args.size() == 1 && component_count(v->args[0]->type) == 1) return v->args[0];
        int first = 0;
        for (const auto& a : v->args) {
            const int n = component_count(a->type);
            if (i < first + n) return n == 1 ? a : make_swizzle(a, i - first);
            first += n;
        }
    }
    auto n = make(type::f32, op::swizzle, {v});
    n->index = i;
    return n;
}

node_ptr make_construct(type t, std::vector<node_ptr> args) {
    int total = 0;
    for (const auto& a : args) total += component_count(a->type);
    require(args.size() == 1 ? total == 1 || total == component_count(t) : total == component_count(t), "components",
            "do not add up to the vector size");
    // vecN(v.x, v.y, ...) of a whole vecN v is v.
    if (int(args.size()) == component_count(t) && args[0]->op == op::swizzle && args[0]->args[0]->type == t) {
        bool whole = true;
        for (std::size_t i = 0; i < args.size(); ++i)
            whole = whole && args[i]->op == op::swizzle && args[i]->index == int(i) && args[i]->args[0] == args[0]->args[0];
        if (whole) return args[0]->args[0];
    }
    return make(t, op::construct, std::move(args));
}

node_ptr make_unary(op o, const node_ptr& a) {
    if (o == op::negate && is_constant(a, type::f32)) return make_constant(-a->value);
    if (o == op::logical_not && is_constant(a, type::boolean)) return make_bool_constant(a->value == 0.f);
    return make(a->type, o, {a});
}

node_ptr make_binary(op o, type t, const node_ptr& a, const node_ptr& b) {
    // Fold in float, the arithmetic of the CPU float instantiation and of GLSL's float.
    if (is_constant(a, type::f32) && is_constant(b, type::f32)) {
        const float x = a->value, y = b->value;
        switch (o) {
            case op::add: return make_constant(x + y);
            case op::subtract: return make_constant(x - y);
            case op::multiply: return make_constant(x * y);
            case op::divide: return make_constant(x / y);
            case op::less: return make_bool_constant(x < y);
            case op::greater: return make_bool_constant(x > y);
            case op::less_equal: return make_bool_constant(x <= y);
            case op::greater_equal: return make_bool_constant(x >= y);
            case op::equal: return make_bool_constant(x == y);
            case op::not_equal: return make_bool_constant(x != y);
            default: break;
        }
    }
    if (is_constant(a, type::boolean) && is_constant(b, type::boolean)) {
        const bool x = a->value != 0.f, y = b->value != 0.f;
        switch (o) {
            case op::logical_and: return make_bool_constant(x && y);
            case op::logical_or: return make_bool_constant(x || y);
            case op::equal: return make_bool_constant(x == y);
            case op::not_equal: return make_bool_constant(x != y);
            default: break;
        }
    }
    return make(t, o, {a, b});
}

node_ptr make_call(type t, std::string function, std::vector<node_ptr> args) {
    return make(t, op::call, std::move(args), std::move(function));
}

node_ptr make_select(const node_ptr& c, const node_ptr& a, const node_ptr& b) {
    require(c->type == type::boolean, "select", "condition is not a boolean");
    require(a->type == b->type, "select", "operands differ in type");
    if (is_constant(c, type::boolean)) return c->value != 0.f ? a : b;
    if (a == b) return a;
    return make(a->type, op::select, {c, a, b});
}

}  // namespace detail
}  // namespace bounce::glsl
