#!/usr/bin/env python3
"""Tests of check_function_size.py on tests/data/function_size/sample_functions.txt, whose functions carry
their length in a '// N lines' comment on their opening brace's line (hand-counted, confirmed by
clang-tidy's readability-function-size)."""

import io
import os
import re
import sys
import unittest
from contextlib import redirect_stderr, redirect_stdout

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_function_size  # noqa: E402

SAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data",
                      "function_size", "sample_functions.txt")


def expected_lengths(text):
    """{opening line: length} from the fixture's '// N lines' comments."""
    out = {}
    for number, line in enumerate(text.splitlines(), start=1):
        m = re.search(r"// (\d+) lines", line)
        if m:
            out[number] = int(m.group(1))
    return out


def run(*args):
    """main()'s exit code and stdout for the command line `args`."""
    out, err = io.StringIO(), io.StringIO()
    sys.argv = ["check_function_size.py", *args]
    with redirect_stdout(out), redirect_stderr(err):
        try:
            code = check_function_size.main()
        except SystemExit as e:  # argparse's usage errors
            code = e.code
    return code, out.getvalue()


class FunctionSize(unittest.TestCase):
    def setUp(self):
        with open(SAMPLE, encoding="utf-8") as f:
            self.text = f.read()

    def test_every_function_and_only_functions_are_found_with_their_length(self):
        found = {line: lines for _, line, lines in check_function_size.functions(self.text)}
        self.assertEqual(found, expected_lengths(self.text))

    def test_operators_and_constructors_are_named(self):
        names = [name for name, _, _ in check_function_size.functions(self.text)]
        self.assertEqual(names, ["Short", "Tricky", "Point", "Point", "operator()", "operator<",
                                 "Twice", "CFunction", "Point_Long"])

    def test_functions_over_the_limit_fail_the_check_naming_each(self):
        code, out = run("--max-lines", "5", SAMPLE)
        self.assertEqual(code, 1)
        self.assertEqual([line.split(": ")[1] for line in out.splitlines()],
                         ["Twice is 6 lines (max 5)", "Point_Long is 12 lines (max 5)"])

    def test_within_the_limit_passes(self):
        code, out = run("--max-lines", "12", SAMPLE)
        self.assertEqual(code, 0)
        self.assertIn("all 9 functions within 12 lines", out)

    def test_a_missing_path_is_a_usage_error(self):
        code, _ = run(SAMPLE + ".missing")
        self.assertEqual(code, 2)


if __name__ == "__main__":
    unittest.main()
