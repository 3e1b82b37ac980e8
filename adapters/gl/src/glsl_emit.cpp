// Printing an expression graph as a GLSL function: structural sharing, locals for shared
// nodes, precedence-aware parentheses, exact float literals.
#include <bounce/glsl/emit.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <unordered_map>

namespace bounce::glsl {

std::string float_literal(float v) {
    if (!std::isfinite(v)) {
        char buf[48];
        const auto bits = std::bit_cast<std::uint32_t>(v);
        std::snprintf(buf, sizeof buf, "uintBitsToFloat(0x%08xu)", unsigned(bits));
        return buf;
    }
    // Shortest decimal that parses back to the same float (to_chars' round-trip guarantee);
    // GLSL compilers read literals with a correctly rounded strtof.
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    std::string s(buf, r.ptr);
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return s;
}

namespace detail {
namespace {

// GLSL 4.50 keywords and reserved words that could be mistaken for a name, and the
// built-ins the emitter calls (a parameter of that name would hide the function).
constexpr std::array reserved = {
    "attribute", "const", "uniform", "varying", "buffer", "shared", "coherent", "volatile", "restrict",
    "readonly", "writeonly", "atomic_uint", "layout", "centroid", "flat", "smooth", "noperspective",
    "patch", "sample", "break", "continue", "do", "for", "while", "switch", "case", "default", "if",
    "else", "subroutine", "in", "out", "inout", "float", "double", "int", "void", "bool", "true",
    "false", "invariant", "precise", "discard", "return", "mat2", "mat3", "mat4", "dmat2", "dmat3",
    "dmat4", "vec2", "vec3", "vec4", "ivec2", "ivec3", "ivec4", "bvec2", "bvec3", "bvec4", "dvec2",
    "dvec3", "dvec4", "uint", "uvec2", "uvec3", "uvec4", "lowp", "mediump", "highp", "precision",
    "struct", "common", "partition", "active", "asm", "class", "union", "enum", "typedef", "template",
    "this", "resource", "goto", "inline", "noinline", "public", "static", "extern", "external",
    "interface", "long", "short", "half", "fixed", "unsigned", "superp", "input", "output", "filter",
    "sizeof", "cast", "namespace", "using", "main",
    "sqrt", "inversesqrt", "abs", "exp", "log", "sin", "cos", "floor", "normalize", "pow", "atan",
    "min", "max", "mix", "dot", "length", "cross", "uintBitsToFloat"};

bool is_leaf(const node& n) { return n.op == op::constant || n.op == op::parameter; }

// Precedence levels of GLSL (= C): smaller binds tighter.
constexpr int primary = 0, postfix = 1, unary = 2, ternary = 13;

int precedence(op o) {
    switch (o) {
        case op::swizzle: return postfix;
        case op::negate:
        case op::logical_not: return unary;
        case op::multiply:
        case op::divide: return 3;
        case op::add:
        case op::subtract: return 4;
        case op::less:
        case op::greater:
        case op::less_equal:
        case op::greater_equal: return 6;
        case op::equal:
        case op::not_equal: return 7;
        case op::logical_and: return 11;
        case op::logical_or: return 12;
        case op::select: return ternary;
        default: return primary;
    }
}

const char* symbol(op o) {
    switch (o) {
        case op::add: return " + ";
        case op::subtract: return " - ";
        case op::multiply: return " * ";
        case op::divide: return " / ";
        case op::less: return " < ";
        case op::greater: return " > ";
        case op::less_equal: return " <= ";
        case op::greater_equal: return " >= ";
        case op::equal: return " == ";
        case op::not_equal: return " != ";
        case op::logical_and: return " && ";
        case op::logical_or: return " || ";
        default: return "?";
    }
}

// One distinct value of the function: nodes that are the same object, or structurally
// equal (same operation on the same distinct values), are one item.
struct item {
    const node* n = nullptr;
    std::vector<int> args;
    int uses = 0;
    bool local = false;
    std::string text;
    int prec = primary;
};

class printer {
public:
    int visit(const node_ptr& n) {
        if (const auto it = seen_.find(n.get()); it != seen_.end()) return it->second;
        std::vector<int> args;
        args.reserve(n->args.size());
        for (const auto& a : n->args) args.push_back(visit(a));
        std::string key = std::to_string(int(n->op)) + ':' + std::to_string(int(n->type)) + ':' +
                          std::to_string(std::bit_cast<std::uint32_t>(n->value)) + ':' + std::to_string(n->index) + ':' +
                          n->name;
        for (int a : args) key += ',' + std::to_string(a);
        int id;
        if (const auto c = canonical_.find(key); c != canonical_.end()) {
            id = c->second;
        } else {
            id = int(items_.size());
            item it;
            it.n = n.get();
            it.args = std::move(args);
            items_.push_back(std::move(it));
            canonical_.emplace(std::move(key), id);
        }
        seen_.emplace(n.get(), id);
        return id;
    }

    // Decides which items become locals and prints them; returns the local declarations.
    std::string print_locals(const std::vector<int>& roots, const std::string& prefix) {
        for (const auto& it : items_)
            for (int a : it.args) ++items_[std::size_t(a)].uses;
        for (int r : roots) ++items_[std::size_t(r)].uses;

        std::string body;
        int next_local = 0;
        // Arguments were visited before their users, so ids are in dependency order.
        for (auto& it : items_) {
            const node& n = *it.n;
            if (is_leaf(n)) it.local = false;
            else if (n.op == op::swizzle) {
                // v.x of a named v is as cheap as a name; of an expression used once via
                // several swizzles, the swizzle itself is what is shared.
                const auto& v = items_[std::size_t(it.args[0])];
                it.local = !(is_leaf(*v.n) || v.local) && it.uses > 1;
            } else
                it.local = it.uses > 1;
            print(it);
            if (it.local) {
                const std::string local = prefix + std::to_string(next_local++);
                body += std::string("    ") + type_name(n.type) + " " + local + " = " + it.text + ";\n";
                it.text = local;
                it.prec = primary;
            }
        }
        return body;
    }

    const std::string& text(int id) const { return items_[std::size_t(id)].text; }

private:
    // The operand's text, parenthesized where the parent's precedence needs it.
    std::string operand(int id, int parent_prec, bool right) const {
        const auto& a = items_[std::size_t(id)];
        // A right operand that starts with a minus sign gets parentheses too: "x - (-1.0)"
        // reads better than "x - -1.0", and "--" would be GLSL's decrement.
        const bool minus_after_operator = right && parent_prec > unary && !a.text.empty() && a.text[0] == '-';
        if (!(a.prec > parent_prec || (right && a.prec == parent_prec) || minus_after_operator)) return a.text;
        // Built by append, not "(" + text + ")": see GCC bug 105329 below.
        std::string s;
        s.reserve(a.text.size() + 2);
        s += '(';
        s += a.text;
        s += ')';
        return s;
    }

    void print(item& it) const {
        const node& n = *it.n;
        it.prec = precedence(n.op);
        switch (n.op) {
            case op::constant:
                if (n.type == type::boolean) {
                    it.text = n.value != 0.f ? "true" : "false";
                } else {
                    it.text = float_literal(n.value);
                    if (it.text[0] == '-') it.prec = unary;
                }
                break;
            case op::parameter: it.text = n.name; break;
            case op::swizzle:
                it.text = operand(it.args[0], postfix, false) + "." + "xyzw"[n.index];
                break;
            case op::negate:
            case op::logical_not:
            {
                // Built by append: GCC 12 misreports -Wrestrict for short string literals
                // assigned or prepended to std::string at -O3 (GCC bug 105329).
                std::string s(1, n.op == op::negate ? '-' : '!');
                s += operand(it.args[0], unary, true);
                it.text = std::move(s);
                break;
            }
            case op::construct:
            case op::call: {
                it.text = (n.op == op::construct ? std::string(type_name(n.type)) : n.name) + "(";
                for (std::size_t i = 0; i < it.args.size(); ++i)
                    it.text += (i ? ", " : "") + operand(it.args[i], ternary, false);
                it.text += ")";
                break;
            }
            case op::select:
                it.text = operand(it.args[0], ternary - 1, false) + " ? " + operand(it.args[1], ternary - 1, false) +
                          " : " + operand(it.args[2], ternary - 1, false);
                break;
            default:  // binary operators, left-associative
                it.text = operand(it.args[0], it.prec, false) + symbol(n.op) + operand(it.args[1], it.prec, true);
                break;
        }
    }

    std::unordered_map<const node*, int> seen_;
    std::unordered_map<std::string, int> canonical_;
    std::vector<item> items_;
};

bool is_local_name(const std::string& name, const std::string& prefix) {
    return name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
           std::all_of(name.begin() + std::ptrdiff_t(prefix.size()), name.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

void check_identifier(std::string_view name, const char* what) {
    const auto fail = [&](const char* why) { throw parameter_error(what, "'" + std::string(name) + "' " + why); };
    if (name.empty()) fail("is empty");
    const auto alpha = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
    if (!alpha(name[0])) fail("is not a GLSL identifier");
    for (char c : name)
        if (!alpha(c) && !(c >= '0' && c <= '9')) fail("is not a GLSL identifier");
    if (name.find("__") != std::string_view::npos) fail("contains '__', reserved in GLSL");
    if (name.substr(0, 3) == "gl_") fail("starts with 'gl_', reserved in GLSL");
    for (const char* r : reserved)
        if (name == r) fail("is a GLSL keyword or a built-in function");
}

std::string print_function(const std::string& return_type, const std::string& name,
                           const std::vector<std::string>& parameter_declarations,
                           const std::vector<std::string>& parameter_names, const std::vector<output>& outputs) {
    std::string prefix = "t";
    while (std::any_of(parameter_names.begin(), parameter_names.end(),
                       [&](const std::string& p) { return is_local_name(p, prefix); }))
        prefix += "_";

    printer p;
    std::vector<int> roots;
    for (const auto& o : outputs) roots.push_back(p.visit(o.value));
    std::string out = return_type + " " + name + "(";
    for (std::size_t i = 0; i < parameter_declarations.size(); ++i) out += (i ? ", " : "") + parameter_declarations[i];
    out += ") {\n" + p.print_locals(roots, prefix);
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        if (outputs[i].target.empty()) out += "    return " + p.text(roots[i]) + ";\n";
        else out += "    " + outputs[i].target + " = " + p.text(roots[i]) + ";\n";
    }
    return out + "}\n";
}

}  // namespace detail

function_set& function_set::add_source(const std::string& name, std::string text) {
    for (const auto& [n, t] : functions_)
        if (n == name) {
            if (t != text) throw parameter_error("name", "two different functions are both named '" + name + "'");
            return *this;
        }
    functions_.emplace_back(name, std::move(text));
    return *this;
}

bool function_set::contains(std::string_view name) const noexcept {
    return std::any_of(functions_.begin(), functions_.end(), [&](const auto& f) { return f.first == name; });
}

std::string function_set::source() const {
    std::string s;
    for (const auto& [n, t] : functions_) s += (s.empty() ? "" : "\n") + t;
    return s;
}

}  // namespace bounce::glsl
