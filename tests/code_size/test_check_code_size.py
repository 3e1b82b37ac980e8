#!/usr/bin/env python3
"""scripts/check_code_size.py on generated sources: it reports a function one line over the
limit and a file one line over, not those at the limit, and braces in comments, literals and
preprocessor lines do not move where a function ends."""

import os
import subprocess
import sys
import tempfile
import unittest

CHECKER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "check_code_size.py")


def function(name, lines, body_line="    x += 1;"):
    """A free function of exactly `lines` lines, signature and closing brace included."""
    return "\n".join([f"inline int {name}(int x) {{"] + [body_line] * (lines - 3) + ["    return x;", "}"]) + "\n"


class CheckCodeSize(unittest.TestCase):
    def check(self, files, *extra):
        """(exit status, reported lines) of the checker over `files` ({path: text})."""
        with tempfile.TemporaryDirectory() as root:
            for path, text in files.items():
                os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
                with open(os.path.join(root, path), "w") as f:
                    f.write(text)
            run = subprocess.run([sys.executable, CHECKER, "--root", root, *extra, "include"],
                                 capture_output=True, text=True)
        return run.returncode, run.stdout.splitlines()

    def test_a_function_of_121_lines_is_reported_and_one_of_120_is_not(self):
        status, lines = self.check({"include/a.hpp": function("long_one", 121) + function("at_limit", 120)})
        self.assertEqual(status, 1)
        self.assertEqual(lines, ["include/a.hpp:1: function long_one is 121 lines (limit 120)"])

    def test_a_file_of_701_lines_is_reported_and_one_of_700_is_not(self):
        status, lines = self.check({"include/long.cpp": "// x\n" * 701, "include/at_limit.cpp": "// x\n" * 700})
        self.assertEqual(status, 1)
        self.assertEqual(lines, ["include/long.cpp: 701 lines (limit 700)"])

    def test_nothing_over_the_limits_exits_0(self):
        self.assertEqual(self.check({"include/a.hpp": function("f", 20)}), (0, []))

    def test_braces_in_comments_literals_and_preprocessor_lines_are_not_code(self):
        # Each opening brace below, if counted, would make `f` swallow the 200 lines of
        # `g` .. `k` after it; each closing brace would end `long_one` at its first line.
        tricky = [
            '    const char* s = "{ \\" {";',
            "    const char c = '{';",
            "    // {",
            "    /* { */",
            '    const char* r = R"glsl(void main() { "}" )glsl";',
            '    const char* r2 = R"(})";',
            "#define OPEN {",
            "    const int million = 1'000'000;",
            "    const char q = '\\'';",
        ]
        text = "\n".join(["inline int f(int x) {"] + tricky + ["    return x;", "}"]) + "\n"
        text += "".join(function(name, 40) for name in "ghijk")
        closing = ['    const char* s = "}";', "    // }", "    const char c = '}';", '    auto r = R"x(})x";']
        text += function("long_one", 125, body_line=closing[0]).replace(closing[0], closing[1], 1)
        text += "\n".join(["inline int m(int x) {"] + closing + ["    return x;", "}"]) + "\n"
        status, lines = self.check({"include/a.hpp": text})
        self.assertEqual(lines, [f"include/a.hpp:{len(tricky) + 3 + 200 + 1}: function long_one is 125 lines (limit 120)"])

    def test_glsl_in_a_raw_string_counts_as_lines_of_its_function(self):
        glsl = "\n".join(["inline const char* shader() {", '    return R"glsl('] + ["    x = x * 2.0;"] * 120 +
                         [')glsl";', "}"]) + "\n"
        status, lines = self.check({"include/a.cpp": glsl})
        self.assertEqual(lines, ["include/a.cpp:1: function shader is 124 lines (limit 120)"])

    def test_a_lambda_is_part_of_its_enclosing_function(self):
        body = ["    auto step = [&](int y) {"] + ["        y += 1;"] * 118 + ["        return y;", "    };"]
        text = "\n".join(["int outer(int x) {"] + body + ["    return step(x);", "}"]) + "\n"
        self.assertEqual(self.check({"include/a.cpp": text})[1],
                         ["include/a.cpp:1: function outer is 124 lines (limit 120)"])

    def test_member_functions_in_and_out_of_class_constructors_and_templates(self):
        member = ["        x_ += 1;"] * 119
        text = "\n".join(
            ["namespace n::inline family {", "template <class T = int>", "class widget : public base<T> {", "  public:",
             "    explicit widget(int x, std::array<int, 2> a = {}) : x_{x}, y_(a[0]), z_{std::size_t(x)} {"] + member +
             ["    }", "    int get() const noexcept { return x_; }",
              "    std::array<double, std::size_t(3)> table{};",
              "    int x_ = 0;", "};", "", "template <class T>", "auto widget<T>::step(int y) -> int {"] + member +
            ["    return y;", "}", "bool operator==(const widget<int>& a, const widget<int>& b) {"] + member +
            ["    return true;", "}", "}  // namespace n::inline family"]) + "\n"
        self.assertEqual(self.check({"include/w.hpp": text})[1], [
            "include/w.hpp:5: function widget is 121 lines (limit 120)",
            # From its template header on.
            "include/w.hpp:131: function widget::step is 123 lines (limit 120)",
            "include/w.hpp:254: function operator== is 122 lines (limit 120)",
        ])

    def test_classes_namespaces_and_initializers_are_not_functions(self):
        members = "".join(f"    int f{k}() const {{ return {k}; }}\n" for k in range(150))
        table = "".join(f"    {{{k}, {k + 1}}},\n" for k in range(150))
        text = ("namespace a {\nstruct big {\n" + members + "};\n"
                "inline constexpr int table[][2] = {\n" + table + "};\n"
                "inline const auto short_lambda = [](int x) { return x; };\n}  // namespace a\n")
        self.assertEqual(self.check({"include/a.hpp": text}), (0, []))

    def test_the_limits_can_be_set(self):
        status, lines = self.check({"include/a.hpp": function("f", 30)}, "--max-function-lines", "29",
                                   "--max-file-lines", "29")
        self.assertEqual(lines, ["include/a.hpp: 30 lines (limit 29)",
                                 "include/a.hpp:1: function f is 30 lines (limit 29)"])


if __name__ == "__main__":
    unittest.main()
