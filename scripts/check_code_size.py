#!/usr/bin/env python3
"""Finds C++ functions longer than 120 lines and files longer than 700 lines.

usage: check_code_size.py [--root DIR] [--max-function-lines N] [--max-file-lines N] [PATH ...]

PATHs (files or folders, relative to --root; default: include adapters) are searched for
.hpp/.cpp/.h/.cc/.inl files. Exits 1 and prints one line per finding when a limit is
exceeded, 0 otherwise.

A function is counted from the first line of its declaration (template header included) to
its closing brace. Free functions, member functions defined in or out of their class,
constructors (with their initializer lists) and lambdas stored at namespace or class scope
count as functions; a lambda or local class inside a function is part of that function, and
so is text inside its string literals (GLSL in a raw string counts as lines of the function
that holds it). Braces in comments, string and character literals, raw strings and
preprocessor lines are not code and are ignored.
"""

import argparse
import os
import re
import sys

SOURCE_SUFFIXES = (".hpp", ".cpp", ".h", ".cc", ".inl")
IDENTIFIER_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_")
RAW_PREFIXES = ("u8R", "uR", "UR", "LR", "R")


def _identifier_before(text, end):
    """The identifier or number token that ends just before text[end]."""
    start = end
    while start > 0 and text[start - 1] in IDENTIFIER_CHARS:
        start -= 1
    return text[start:end]


def code_only(text):
    """text with comments, literals' contents and preprocessor lines replaced by spaces.

    Newlines are kept, so line numbers and line counts stay those of the file; quotes stay,
    so a literal still separates the tokens around it.
    """
    out = list(text)
    n = len(text)
    i = 0
    line_start = True  # only whitespace since the last newline

    def blank(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if c == "\n":
            line_start = True
            i += 1
            continue
        if line_start and c == "#":
            # A preprocessor line, continued by backslash-newline.
            j = i
            while j < n and text[j] != "\n":
                j += 2 if text[j] == "\\" and j + 1 < n else 1
            blank(i, j)
            i = j
            continue
        if not c.isspace():
            line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            blank(i, j)
            i = j
        elif c == '"':
            if _identifier_before(text, i) in RAW_PREFIXES:
                open_paren = text.find("(", i + 1)
                delimiter = text[i + 1:open_paren]
                close = text.find(")" + delimiter + '"', open_paren + 1)
                j = n if close < 0 else close + len(delimiter) + 1
                blank(i + 1, j)
                i = j + 1
            else:
                j = i + 1
                while j < n and text[j] != '"' and text[j] != "\n":
                    j += 2 if text[j] == "\\" else 1
                blank(i + 1, j)
                i = j + 1
        elif c == "'":
            token = _identifier_before(text, i)
            if token[:1].isdigit():
                i += 1  # a digit separator: 1'000'000
                continue
            j = i + 1
            while j < n and text[j] != "'" and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            blank(i + 1, j)
            i = j + 1
        else:
            i += 1
    return "".join(out)


def _strip_balanced(head, start, open_char, close_char):
    """Index just past the bracket group of head that opens at head[start]."""
    depth = 0
    for k in range(start, len(head)):
        if head[k] == open_char:
            depth += 1
        elif head[k] == close_char:
            depth -= 1
            if depth == 0:
                return k + 1
    return len(head)


def _without_template_headers(head):
    """head with every `template <...>` header removed."""
    while True:
        match = re.search(r"\btemplate\s*<", head)
        if match is None:
            return head
        end = _strip_balanced(head, match.end() - 1, "<", ">")
        head = head[:match.start()] + " " + head[end:]


OPERATOR_NAME = re.compile(r"\boperator\b\s*(\(\s*\)|[^(;{}]+?(?=\s*\())")
SCOPE_KEYWORD = re.compile(r"\b(namespace|class|struct|union|enum|extern)\b")
ACCESS_LABEL = re.compile(r"^\s*(?:(?:public|private|protected)\s*:(?!:)\s*)+")


def _depth_zero(head):
    """head with its operator names replaced by `operator_name`, the template headers removed
    and everything inside (), [], {} and template arguments <> removed: what is left at
    bracket depth 0, with the outermost brackets kept. Angle brackets count only outside
    parentheses, where a declaration's `<` opens template arguments."""
    head = _without_template_headers(OPERATOR_NAME.sub(" operator_name ", head)).replace("->", " returns ")
    out = []
    stack = []
    for c in head:
        if c in "([{" or c == "<" and all(b == "<" for b in stack):
            if not stack:
                out.append(c)
            stack.append(c)
        elif stack and c in ")]}>" and (c != ">" or stack[-1] == "<"):
            stack.pop()
            if not stack:
                out.append(c)
        elif not stack:
            out.append(c)
    return "".join(out)


def classify(head):
    """What the brace after head opens: 'scope' (namespace, class...), 'function', 'lambda'
    (a lambda stored at namespace or class scope), 'initializer' (a braced initializer or
    anything else that is not a definition)."""
    flat = _depth_zero(head)
    if SCOPE_KEYWORD.search(flat.split("(", 1)[0]):
        return "scope"
    assignment = re.search(r"(?<![=!<>+\-*/%&|^])=(?!=)", flat)
    if assignment is not None:
        return "lambda" if flat[assignment.end():].strip().startswith("[") else "initializer"
    return "function" if "(" in flat else "initializer"


def _name_of(head):
    """The function's (qualified) name, or the variable's for a lambda."""
    label = ACCESS_LABEL.match(head)
    flat = _depth_zero(head[label.end():] if label else head)
    operator = OPERATOR_NAME.search(head)
    lambda_name = re.search(r"(\w+)\s*=\s*\[", flat)
    if lambda_name is not None:
        return lambda_name.group(1)
    names = [name.replace("<>", "") for name in re.findall(r"([\w:~<>]*)\s*\(", flat)]
    names = [name for name in names if name and name not in ("requires", "noexcept", "decltype", "alignas")]
    if not names:
        return "?"
    name = names[0]
    if operator is not None and name.endswith("operator_name"):
        name = name[:-len("operator_name")] + re.sub(r"\s+", " ", operator.group(0)).replace("operator ", "operator", 1) \
            if not operator.group(1)[:1].isalpha() else name[:-len("operator_name")] + re.sub(r"\s+", " ", operator.group(0))
    return name


def _in_mem_initializers(head):
    """Whether head is a constructor's signature followed by `:` and mem-initializers,
    so that a brace after a name (x_{a}) initializes a member instead of opening the body."""
    flat = _depth_zero(head)
    close = flat.find(")")
    return close >= 0 and re.search(r"(?<!:):(?!:)", flat[close:]) is not None


def find_functions(code):
    """(name, first line, last line) of every function definition in code (from code_only)."""
    functions = []
    # Each open brace: its kind, the index where its head started, and its name.
    stack = []
    head_start = 0
    i = 0
    n = len(code)
    while i < n:
        c = code[i]
        inside_function = any(kind in ("function", "lambda") for kind, _, _ in stack)
        if inside_function or (stack and stack[-1][0] == "initializer"):
            if c == "{":
                stack.append(("nested", i, ""))
            elif c == "}":
                kind, start, name = stack.pop()
                if kind in ("function", "lambda"):
                    functions.append((name, code.count("\n", 0, start) + 1, code.count("\n", 0, i) + 1))
                if kind != "nested":
                    head_start = i + 1
            i += 1
            continue
        if c == ";":
            head_start = i + 1
        elif c == "}":
            if stack:
                stack.pop()
            head_start = i + 1
        elif c == "{":
            head = code[head_start:i]
            if head.count("(") + head.count("[") > head.count(")") + head.count("]"):
                # A brace inside the signature's brackets: a default argument's {} or a lambda.
                i = _strip_balanced(code, i, "{", "}")
                continue
            prior = code[:i].rstrip()
            if _in_mem_initializers(head) and prior and (prior[-1] in IDENTIFIER_CHARS or prior[-1] == ">"):
                # x_{a} in a constructor's initializer list: part of the head.
                i = _strip_balanced(code, i, "{", "}")
                continue
            kind = classify(head)
            label = ACCESS_LABEL.match(head)
            start = head_start + (label.end() if label else 0)
            while start < i and code[start].isspace():
                start += 1
            stack.append((kind, start, _name_of(head) if kind in ("function", "lambda") else ""))
            head_start = i + 1
        i += 1
    return functions


def source_files(root, paths):
    for path in paths:
        full = os.path.join(root, path)
        if os.path.isfile(full):
            yield path
            continue
        for folder, dirs, files in os.walk(full):
            dirs.sort()
            for name in sorted(files):
                if name.endswith(SOURCE_SUFFIXES):
                    yield os.path.relpath(os.path.join(folder, name), root)


def findings(root, paths, max_function_lines, max_file_lines):
    for path in source_files(root, paths):
        with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
            text = f.read()
        line_count = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
        if line_count > max_file_lines:
            yield f"{path}: {line_count} lines (limit {max_file_lines})"
        for name, first, last in find_functions(code_only(text)):
            length = last - first + 1
            if length > max_function_lines:
                yield f"{path}:{first}: function {name} is {length} lines (limit {max_function_lines})"


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."),
                        help="folder the paths are relative to (default: the repository)")
    parser.add_argument("--max-function-lines", type=int, default=120)
    parser.add_argument("--max-file-lines", type=int, default=700)
    parser.add_argument("paths", nargs="*", default=["include", "adapters"])
    args = parser.parse_args(argv)
    root = os.path.abspath(args.root)
    for path in args.paths:
        if not os.path.exists(os.path.join(root, path)):
            parser.error(f"paths: {path} does not exist under {root}")
    found = list(findings(root, args.paths, args.max_function_lines, args.max_file_lines))
    for line in found:
        print(line)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
