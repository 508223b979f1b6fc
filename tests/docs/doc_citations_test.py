#!/usr/bin/env python3
"""Every test and every repository file a document cites exists.

Usage: python3 tests/docs/doc_citations_test.py SOURCE_DIR

Scans README.md, docs/*.md and bench/campaigns/README.md under SOURCE_DIR for

  - GoogleTest citations, `Suite.Name` inside backticks (both parts identifiers that start
    with an uppercase letter; `Suite.*` cites a whole suite), each of which must be defined by
    TEST(Suite, Name), TEST_F(Suite, Name), TEST_P(Suite, Name) or TYPED_TEST(Suite, Name) in
    a file under tests/ (for TEST_P, Suite may also be an INSTANTIATE_TEST_SUITE_P prefix of
    the fixture);
  - repository paths (core/..., campaigns/..., tests/..., and the other top-level folders)
    ending in a file extension, in backticks or in plain text, each of which must exist.
    Braces are expanded (`campaigns/spec/cases.{h,cc}` cites two files); paths with a
    wildcard, angle brackets or a placeholder in capitals (NAME, DIR, ...) are skipped.

Prints every failure as `FILE:LINE: cites WHAT which does not exist`, then a closing line
`N passed, M failed`. Exit status 0 when nothing failed, 1 otherwise, 2 on bad usage.
Standard library only.
"""

import glob
import os
import re
import sys

ROOTS = ("core", "faults", "campaigns", "reports", "tests", "app", "bench", "tools", "docs",
         "examples", "python", "include", "deploy")
EXTENSIONS = ("cc", "h", "c", "json", "md", "sh", "py", "urdf", "sbatch", "yaml", "ipynb",
              "in", "txt", "diff", "supp", "dict", "csv", "sha256", "cmake")
# Capitalised file stems that are real names, not placeholders.
REAL_CAPITALS = {"README", "LICENSE", "CHANGELOG", "CONTRIBUTING", "NOTICE", "AUTHORS",
                 "CMAKELISTS"}

IDENT = r"[A-Z][A-Za-z0-9_]*"
# A test citation: not part of a longer dotted, slashed or called name.
TEST_CITATION = re.compile(
    r"(?<![\w./:-])(" + IDENT + r")\.(" + IDENT + r"|\*)(?![\w./(-])")
# A path: a top-level folder, then path characters; checked for an extension afterwards.
PATH_TOKEN = re.compile(
    r"(?<![\w./~$-])((?:" + "|".join(ROOTS) + r")/[\w./*<>{},+@-]*)")
SPAN = re.compile(r"`([^`\n]+(?:\n(?!\s*\n)[^`\n]*)*)`")
FENCE = re.compile(r"^\s*(```|~~~)")

TEST_DEFINITION = re.compile(
    r"\b(TEST|TEST_F|TEST_P|TYPED_TEST|TYPED_TEST_P)\s*\(\s*(\w+)\s*,\s*(\w+)\s*\)")
INSTANTIATION = re.compile(
    r"\b(?:INSTANTIATE_TEST_SUITE_P|INSTANTIATE_TEST_CASE_P|INSTANTIATE_TYPED_TEST_SUITE_P)"
    r"\s*\(\s*(\w+)\s*,\s*(\w+)\s*,")


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def load_tests(source_dir):
    """(suite, name) pairs defined under tests/, and every suite name."""
    defined = set()
    instantiations = {}  # prefix -> fixtures
    for path in glob.glob(os.path.join(source_dir, "tests", "**", "*"), recursive=True):
        if not os.path.isfile(path) or not path.endswith((".cc", ".cpp", ".cxx", ".h", ".hpp")):
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            text = strip_comments(f.read())
        for _, suite, name in TEST_DEFINITION.findall(text):
            defined.add((suite, name))
        for prefix, fixture in INSTANTIATION.findall(text):
            instantiations.setdefault(prefix, set()).add(fixture)
    for prefix, fixtures in instantiations.items():
        for suite, name in list(defined):
            if suite in fixtures:
                defined.add((prefix, name))
    suites = {suite for suite, _ in defined}
    return defined, suites


def documents(source_dir):
    names = ["README.md"]
    names += sorted(os.path.relpath(p, source_dir)
                    for p in glob.glob(os.path.join(source_dir, "docs", "*.md")))
    names.append(os.path.join("bench", "campaigns", "README.md"))
    return [n for n in names if os.path.isfile(os.path.join(source_dir, n))]


def outside_fences(text):
    """The text with fenced code blocks blanked (newlines kept), for backtick spans."""
    out, fenced = [], False
    for line in text.split("\n"):
        if FENCE.match(line):
            fenced = not fenced
            out.append("")
            continue
        out.append("" if fenced else line)
    return "\n".join(out)


def line_of(text, offset):
    return text.count("\n", 0, offset) + 1


def expand_braces(path):
    """`a/b.{h,cc}` -> [`a/b.h`, `a/b.cc`]; every group of one level, left to right."""
    m = re.search(r"\{([^{}]*)\}", path)
    if not m:
        return [path]
    return [expanded
            for choice in m.group(1).split(",")
            for expanded in expand_braces(path[:m.start()] + choice + path[m.end():])]


def is_placeholder(path):
    if any(c in path for c in "*<>{},"):
        return True
    for word in re.split(r"[/._+@-]", path):
        if re.fullmatch(r"[A-Z][A-Z0-9]*", word) and word.upper() not in REAL_CAPITALS:
            return True
    return False


def file_path(token):
    """The cited file in a path token, or None when it names no file with an extension."""
    token = token.rstrip(".,;:)")
    if token.endswith("/"):
        return None
    base = token.rsplit("/", 1)[-1]
    if "." not in base:
        return None
    if base.rsplit(".", 1)[-1] not in EXTENSIONS:
        return None
    return token


def file_paths(token):
    """The files a path token cites: none, one, or one per choice of its braces."""
    if "{" in token:
        # A brace group may hold commas and end in one, so cut the token after the last brace
        # group's extension, not at the first comma.
        m = re.match(r"[^{}]*(?:\{[^{}]*\}[^{},]*)+", token)
        if not m:
            return []
        token = m.group(0)
        paths = [file_path(p) for p in expand_braces(token)]
    else:
        token = token.split(",", 1)[0]
        paths = [file_path(token)]
    return [p for p in paths if p is not None]


def main(argv):
    if len(argv) != 2 or not os.path.isdir(argv[1]):
        print("usage: doc_citations_test.py SOURCE_DIR", file=sys.stderr)
        return 2
    source_dir = argv[1]
    defined, suites = load_tests(source_dir)
    passed, failures = 0, []
    for doc in documents(source_dir):
        found = []
        with open(os.path.join(source_dir, doc), encoding="utf-8") as f:
            text = f.read()
        seen = set()

        def check(line, what, ok):
            nonlocal passed
            if (line, what) in seen:
                return
            seen.add((line, what))
            if ok:
                passed += 1
            else:
                found.append((line, f"{doc}:{line}: cites {what} which does not exist"))

        spans_text = outside_fences(text)
        for span in SPAN.finditer(spans_text):
            for m in TEST_CITATION.finditer(span.group(1)):
                suite, name = m.group(1), m.group(2)
                line = line_of(spans_text, span.start(1) + m.start())
                if name == "*":
                    check(line, f"{suite}.*", suite in suites)
                else:
                    check(line, f"{suite}.{name}", (suite, name) in defined)
        for m in PATH_TOKEN.finditer(text):
            for path in file_paths(m.group(1)):
                if is_placeholder(path):
                    continue
                check(line_of(text, m.start(1)), path,
                      os.path.isfile(os.path.join(source_dir, path)))
        failures += [message for _, message in sorted(found, key=lambda f: f[0])]
    for failure in failures:
        print(failure)
    print(f"{passed} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
