#!/usr/bin/env python3
"""Self-test of scripts/longfn.py on a small generated tree: it finds exactly the functions over
the limit (not aggregate initialisers, namespaces, classes or constructor initialiser lists), the
files over 500 lines, leaves test files out, and --check fails on an unlisted finding and on a
stale allow-list entry."""
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(os.path.dirname(HERE), "longfn.py")
sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, os.path.dirname(HERE))
import longfn  # noqa: E402


def body(n):
    return "".join(f"  x += {i};\n" for i in range(n))


LONG_CPP = (
    "#include <vector>\n"
    "namespace cf {\nnamespace {\n"
    "constexpr int kTable[] = {\n" + "".join(f"  {i},\n" for i in range(100)) + "};\n"
    "}  // namespace\n"
    "struct Holder {\n  int a_, b_;\n"
    "  Holder(int a) : a_(a), b_{a} {\n" + body(10) + "  }\n"
    "  int method() const {\n" + body(3) + "    return 1;\n  }\n"
    "};\n"
    "int long_one(int x) {  // head + 80 lines + return + closing brace = 83 lines\n" + body(80) + "  return x;\n}\n"
    "int short_one(int x) {\n  auto f = [&](int y) {\n" + body(60) + "    return y; };\n  return f(x);\n}\n"
    "/* a comment with { braces } and a string \"}\" */\n"
    "const char* s = \"{{{\";\n"
    "}  // namespace cf\n"
)


class LongFnTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.root = self.tmp.name
        src = os.path.join(self.root, "modules", "m", "src")
        test = os.path.join(self.root, "modules", "m", "test")
        os.makedirs(src)
        os.makedirs(test)
        with open(os.path.join(src, "a.cpp"), "w") as f:
            f.write(LONG_CPP)
        with open(os.path.join(src, "big.h"), "w") as f:
            f.write("// filler\n" * 501)
        with open(os.path.join(test, "a_test.cpp"), "w") as f:
            f.write(LONG_CPP)  # test files are left out

    def tearDown(self):
        self.tmp.cleanup()

    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, "--root", self.root, *args], capture_output=True, text=True)

    # Exactly the long function and the long file are reported, with the function's length.
    def test_finds_long_function_and_file_only(self):
        found = longfn.findings(self.root, [], False, 80, 500)
        keys = sorted((f[0], f[1], f[3]) for f in found)
        self.assertEqual(keys, [("modules/m/src/a.cpp", "long_one", 83), ("modules/m/src/big.h", None, 501)])

    # Every function is seen with its name: constructor, method, the short function with its lambda.
    def test_function_names_and_lengths(self):
        funcs = longfn.find_functions(longfn.strip_code(LONG_CPP))
        names = {name: last - first + 1 for name, first, last in funcs}
        self.assertEqual(set(names), {"Holder", "method", "long_one", "short_one"})
        self.assertEqual(names["Holder"], 12)
        self.assertEqual(names["short_one"], 65)

    # --all includes the test file's copy of the long function.
    def test_all_includes_tests(self):
        found = longfn.findings(self.root, [], True, 80, 500)
        self.assertIn("modules/m/test/a_test.cpp", {f[0] for f in found})

    # --check: unlisted findings fail; listed ones pass; a stale entry fails; an entry needs a reason.
    def test_check_against_allow_list(self):
        allow = os.path.join(self.root, "allow.txt")
        self.assertEqual(self.run_script("--check", "--allow", allow).returncode, 1)
        with open(allow, "w") as f:
            f.write("# reviewed\nmodules/m/src/a.cpp:long_one  kept long on purpose\nmodules/m/src/big.h  a table\n")
        r = self.run_script("--check", "--allow", allow)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        with open(allow, "a") as f:
            f.write("modules/m/src/a.cpp:short_one  no longer long\n")
        r = self.run_script("--check", "--allow", allow)
        self.assertEqual(r.returncode, 1)
        self.assertIn("no longer over the limits", r.stdout)
        with open(allow, "w") as f:
            f.write("modules/m/src/a.cpp:long_one\n")
        self.assertNotEqual(self.run_script("--check", "--allow", allow).returncode, 0)


if __name__ == "__main__":
    unittest.main()
