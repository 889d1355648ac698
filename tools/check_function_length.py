#!/usr/bin/env python3
"""Lists every function in the C++ sources over a line budget; exits 1 when there is one.

  tools/check_function_length.py                 # src/, 150 lines
  tools/check_function_length.py --max-lines 100 --list src nodelets

A function's length is counted from the first line of its declaration (return type or
template head) to its closing brace, inclusive, as clang's FunctionDecl source range does.
Lambdas and local classes count as part of the function that holds them.

The reader is a tokenizer, not a compiler: comments, string/char literals (raw strings
included) and preprocessor lines are removed, then braces are matched while tracking what
each scope is (namespace, class, function, initializer). A `{` at namespace or class scope
opens a function body when the statement before it has a parameter list and no `=`; in a
constructor's member-initializer list, `name{...}` is an initializer, not the body.
"""
import argparse
import os
import re
import sys

SOURCE_SUFFIXES = (".cpp", ".cc", ".cxx", ".hpp", ".h", ".hh")
TOKEN = re.compile(r"[A-Za-z_]\w*|::|->|==|!=|<=|>=|&&|\|\||\d[\w.']*|\S")


def strip_code(text):
    """Returns text with comments, literals and preprocessor lines blanked; newlines kept."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            # Preprocessor directive, with backslash continuations.
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append("\n")
                    i += 2
                    continue
                i += 1
            continue
        if c == "\n":
            out.append(c)
            line_start = True
            i += 1
            continue
        if c in " \t\r":
            out.append(c)
            i += 1
            continue
        line_start = False
        if text.startswith("//", i):
            while i < n and text[i] != "\n":
                i += 1
            continue
        if text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            out.append("\n" * text.count("\n", i, end))
            i = end
            continue
        raw = re.match(r'(?:u8|u|U|L)?R"([^()\\\s]{0,16})\(', text[i:i + 40])
        if raw and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            close = ")" + raw.group(1) + '"'
            end = text.find(close, i + raw.end())
            end = n if end < 0 else end + len(close)
            out.append('""' + "\n" * text.count("\n", i, end))
            i = end
            continue
        if c in "\"'":
            # A digit separator (1'000) is not a char literal.
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(c)
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
            continue
        out.append(c)
        i += 1
    return "".join(out)


def tokens_with_lines(code):
    for line_no, line in enumerate(code.split("\n"), start=1):
        for match in TOKEN.finditer(line):
            yield match.group(0), line_no


def classify_head(head):
    """Kind of the scope a `{` opens after the statement tokens `head` at namespace/class scope."""
    words = without_template_parameters([t for t, _ in head])
    if not words:
        return "block"
    if "namespace" in words or (words[0] == "extern" and len(words) <= 2):
        return "namespace"
    depth = 0
    has_params = False
    for t in words:
        if t in "([":
            if t == "(":
                has_params = True
            depth += 1
        elif t in ")]":
            depth -= 1
        elif t == "=" and depth == 0:
            # `operator=` / `operator==` are functions; anything else is an initializer.
            k = words.index("=")
            if k == 0 or words[k - 1] != "operator":
                return "block"
        elif depth == 0 and t in ("class", "struct", "union", "enum") and not has_params:
            return "class"
    return "function" if has_params else "block"


def functions_in(path):
    """Yields (name, first_line, last_line) for every function defined in the file."""
    with open(path, encoding="utf-8", errors="replace") as f:
        code = strip_code(f.read())
    stack = []  # kinds of open scopes
    head = []  # tokens of the statement being read at namespace/class scope
    func = None  # (name, first_line, depth at which its body opened)
    init_depth = 0  # brace depth inside a constructor's member initializer `name{...}`
    for tok, line in tokens_with_lines(code):
        in_decl_scope = all(k in ("namespace", "class") for k in stack)
        if func is not None or not in_decl_scope:
            if tok == "{":
                stack.append("inner")
            elif tok == "}":
                stack.pop()
                if func is not None and len(stack) == func[2]:
                    yield func[0], func[1], line
                    func = None
            continue
        if init_depth:
            head.append((tok, line))
            init_depth += {"{": 1, "}": -1}.get(tok, 0)
            continue
        if tok == "{":
            kind = classify_head(head)
            if kind == "function" and in_ctor_initializer(head):
                prev = head[-1][0]
                if re.match(r"\w", prev) or prev == ">":
                    head.append((tok, line))
                    init_depth = 1
                    continue
            if kind == "function":
                func = (function_name(head), head[0][1], len(stack))
                stack.append("function")
            else:
                stack.append(kind)
            head = []
        elif tok == "}":
            if stack:
                stack.pop()
            head = []
        elif tok == ";":
            head = []
        elif tok == ":" and head and head[-1][0] in ("public", "private", "protected"):
            head = []
        else:
            head.append((tok, line))


def without_template_parameters(words):
    """`words` without the parameter lists of `template <...>` (whose `class` is no class)."""
    out = []
    i = 0
    while i < len(words):
        if words[i] == "template" and i + 1 < len(words) and words[i + 1] == "<":
            depth = 0
            i += 1
            while i < len(words):
                depth += {"<": 1, ">": -1}.get(words[i], 0)
                i += 1
                if depth == 0:
                    break
            continue
        out.append(words[i])
        i += 1
    return out


def in_ctor_initializer(head):
    """True when the head reads `... ( params ) [noexcept] : member...`."""
    depth = 0
    seen_params = False
    for t, _ in head:
        if t in "([":
            depth += 1
        elif t in ")]":
            depth -= 1
            if depth == 0:
                seen_params = True
        elif t == ":" and depth == 0 and seen_params:
            return True
    return False


def function_name(head):
    """The qualified name before the parameter list (`Class::method`)."""
    words = [t for t, _ in head]
    if "(" not in words:
        return "?"
    k = words.index("(")
    if k >= 2 and words[k - 2] == "operator":
        name = ["operator" + words[k - 1]]
        j = k - 3
    else:
        name = [words[k - 1]] if k >= 1 else ["?"]
        j = k - 2
    while j >= 1 and words[j] == "::":
        name.insert(0, words[j - 1])
        j -= 2
    if k >= 2 and words[k - 2] == "~":
        name[-1] = "~" + name[-1]
    return "::".join(name)


def source_files(roots):
    for root in roots:
        if os.path.isfile(root):
            yield root
            continue
        for folder, dirs, files in os.walk(root):
            dirs.sort()
            for name in sorted(files):
                if name.endswith(SOURCE_SUFFIXES):
                    yield os.path.join(folder, name)


SELF_TEST_CODE = r"""
// comment with { braces } and a fake f() {
#define MACRO(x) { x; }
namespace a::b {
namespace {
const char* kText = "}{ not code";
const char kBrace = '{';
const auto kRaw = R"x(
} unbalanced in a raw string {
)x";
int table[] = {1, 2, 3};
}  // namespace
struct S {
  S(int x) : x_{x}, y_(x) {
    x_ += 1;
  }
  int get() const { return x_; }
  bool operator==(const S& o) const {
    return x_ == o.x_;
  }
  int x_, y_;
};
template <typename T>
T twice(T t) {
  auto f = [&](int k) {
    return k * 2;
  };
  return f(t);
}
enum class E { kA, kB };
int S_free(int v) noexcept {
  if (v) {
    return 1'000;
  }
  return 0;
}
template <class F, template <class> class G>
void forEach(F&& f) {
  f(Row{1, 2});
}
}  // namespace a::b
"""
SELF_TEST_EXPECTED = [("S", 13, 15), ("get", 16, 16), ("operator==", 17, 19), ("twice", 22, 28),
                      ("S_free", 30, 35), ("forEach", 36, 39)]


def self_test():
    """The reader finds exactly the functions of a made-up file, and a long one fails the budget."""
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "sample.cpp")
        with open(path, "w") as f:
            f.write(SELF_TEST_CODE.lstrip("\n"))
        got = list(functions_in(path))
        if got != SELF_TEST_EXPECTED:
            print(f"self-test FAILED: functions {got}, expected {SELF_TEST_EXPECTED}")
            return 1
        long_path = os.path.join(tmp, "long.cpp")
        with open(long_path, "w") as f:
            f.write("int f() {\n" + "  ++x;\n" * 149 + "}\nint g() {\n" + "  ++x;\n" * 148 + "}\n")
        got = [(n, last - first + 1) for n, first, last in functions_in(long_path)]
        if got != [("f", 151), ("g", 150)]:
            print(f"self-test FAILED: lengths {got}, expected f 151 and g 150")
            return 1
    print("self-test passed")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("roots", nargs="*", default=["src"], help="files or folders (default: src)")
    parser.add_argument("--max-lines", type=int, default=150, help="budget per function (default 150)")
    parser.add_argument("--list", type=int, default=0, metavar="N",
                        help="also print the N longest functions, whatever their length")
    parser.add_argument("--self-test", action="store_true", help="check the reader on made-up code and exit")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    if args.max_lines < 1:
        parser.error(f"--max-lines must be at least 1, got {args.max_lines}")
    found = []
    for path in source_files(args.roots):
        for name, first, last in functions_in(path):
            found.append((last - first + 1, path, first, last, name))
    if not found:
        print(f"check_function_length: no function found under {' '.join(args.roots)}", file=sys.stderr)
        return 2
    found.sort(key=lambda f: (-f[0], f[1], f[2]))
    for length, path, first, last, name in found[:args.list]:
        print(f"{length:5d}  {path}:{first}-{last}  {name}")
    over = [f for f in found if f[0] > args.max_lines]
    for length, path, first, last, name in over:
        print(f"{path}:{first}: {name} is {length} lines (budget {args.max_lines})")
    print(f"{len(found)} functions read, {len(over)} over {args.max_lines} lines")
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
