# SPDX-License-Identifier: Apache-2.0
"""Help, manual pages and everyday usability of every tool: examples at the end of --help, help in
plain words, man pages generated from the same option definitions, "did you mean" suggestions,
'-' as standard output where a stream makes sense, warnings under --quiet, and --strict."""
import json
import os
import re
import struct
import unittest

import clitest
from clitest import ToolTestCase

TOOLS = [t for t in os.environ.get("GLINTBAKE_TOOLS", "").split(",") if t]
SMALL = ["--ndf-res", "16", "--stride", "8", "--sigma0", "4"]
STRICT_WARNINGS = 6


def long_options(text):
    return set(re.findall(r"(?<![\w-])--[a-z][a-z0-9-]+", text))


def write_short_normals(path, size=16):
    """A PFM map whose normals are half unit length: ingest renormalises them, with a warning."""
    values = []
    for _ in range(size * size):
        values += [0.0, 0.0, 0.5]
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (size, size))
        f.write(struct.pack("<%df" % len(values), *values))
    return path


class Help(ToolTestCase):
    def test_help_has_examples_and_plain_words(self):
        for tool in TOOLS:
            out, _ = self.run_ok(tool, "--help")
            self.assertIn("Examples:", out, tool)
            self.assertGreaterEqual(out.count("\n  " + tool + " "), 2, f"{tool}: fewer than two examples")
            self.assertIn("6 warnings under --strict", out, tool)
            self.assertNotIn("ENUM:", out, tool)
            self.assertNotIn("->", out, tool)
            self.assertNotIn("--help-man", out, tool)
            # No CLI11 validator text or flag-value suffixes: values are N, X, TEXT or named choices.
            for internal in ("INT:", "FLOAT:", "UINT", "{false}", "{true}", "POSITIVE", "NONNEGATIVE"):
                self.assertNotIn(internal, out, f"{tool}: {internal!r} in --help")
            self.assertIsNone(re.search(r" in \[\S+ - \S+\]", out), tool)
            for sub in re.findall(r"^  ([a-z][a-z-]+) +[A-Z]", out.split("Subcommands:")[-1], re.M) \
                    if "Subcommands:" in out else []:
                sub_help, _ = self.run_ok(tool, sub, "--help")
                for internal in ("INT:", "FLOAT:", "{false}", "POSITIVE"):
                    self.assertNotIn(internal, sub_help, f"{tool} {sub}: {internal!r} in --help")
                self.assertIsNone(re.search(r" in \[\S+ - \S+\]", sub_help), f"{tool} {sub}")
                # A required option has no default worth showing.
                self.assertIsNone(re.search(r"=\S* REQUIRED", sub_help), f"{tool} {sub}")

    def test_man_page_lists_every_option_of_help(self):
        for tool in TOOLS:
            help_text, _ = self.run_ok(tool, "--help")
            page, _ = self.run_ok(tool, "--help-man")
            self.assertTrue(page.startswith(".TH " + tool.upper() + " 1"), tool)
            self.assertIn(".SH EXAMPLES", page)
            self.assertIn(".SH EXIT STATUS", page)
            plain = page.replace("\\-", "-")
            for option in long_options(help_text):
                self.assertIn(option, plain, f"{tool}: {option} of --help missing from the man page")

    def test_subcommand_help_lists_the_global_options(self):
        out, _ = self.run_ok("glintinfo", "validate", "--help")
        for option in ("--json", "--quiet", "--strict", "--threads", "--depfile"):
            self.assertIn(option, out)
        self.assertIn("Examples:", out)

    def test_ingest_choices_by_name(self):
        out, _ = self.run_ok("ndfgen", "--help")
        self.assertIn("auto|unorm|snorm", out)
        self.assertIn("repeat|clamp", out)


class Suggestions(ToolTestCase):
    def test_mistyped_option(self):
        m = self.mapgen("beckmann", "m.png", "--size", "16")
        err = self.assert_fails(clitest.BAD_ARGS, "ndfgen", m, "-o", self.path("m.gbk"), "--sigam0", "4")
        self.assertIn("did you mean '--sigma0'", err)

    def test_mistyped_subcommand(self):
        err = self.assert_fails(clitest.BAD_ARGS, "glintinfo", "infoo", "x.gbk")
        self.assertIn("did you mean 'info'", err)


class Streams(ToolTestCase):
    def test_inputs_from_standard_input(self):
        """'-' reads a normal map or a container from standard input: the same asset as from the file
        (its input named '-' in the metadata, left out of the depfile), and clear refusals where a
        stream cannot work."""
        m = self.mapgen("beckmann", "m.png", "--size", "16")
        with open(m, "rb") as f:
            png = f.read()
        from_file, from_stdin = self.path("file.gbk"), self.path("stdin.gbk")
        self.run_ok("ndfgen", m, "-o", from_file, *SMALL, "--quiet")
        code, _, err = clitest.run("ndfgen", "-", "-o", from_stdin, *SMALL, "--quiet", "--depfile",
                                   self.path("stdin.d"), stdin=png)
        self.assertEqual(code, 0, err)
        info = self.run_json("glintinfo", "info", from_stdin)
        self.assertEqual([i["name"] for i in info["metadata"]["inputs"]], ["-"])
        with open(self.path("stdin.d")) as f:
            self.assertNotIn("-", f.read().split(":", 1)[1].split())
        query = ["--at", "5.5,7.5", "--sigma", "2", "--s", "0.05,0.02"]
        a = self.run_json("glintquery", "point", from_file, *query)
        with open(from_stdin, "rb") as f:
            asset = f.read()
        code, out, err = clitest.run("glintquery", "point", "-", *query, "--json", stdin=asset)
        self.assertEqual(code, 0, err)
        self.assertEqual(json.loads(out)["value"], a["value"])
        code, out, _ = clitest.run("glintinfo", "validate", "-", stdin=asset)
        self.assertEqual(code, 0)
        self.assertIn("-: valid", out)
        # Refusals: one line, the documented code, nothing left behind.
        out = self.path("x.gbk")
        self.assert_fails(clitest.BAD_ARGS, "tensorpack", "-", *SMALL, stdin=png)
        self.assert_fails(clitest.INVALID, "ndfgen", "-", "-o", out, *SMALL, stdin=b"", outputs=[out])
        self.assert_fails(clitest.INVALID, "ndfgen", "-", "-o", out, *SMALL, stdin=b"not an image", outputs=[out])
        self.assert_fails(clitest.BAD_ARGS, "glintinfo", "diff", "-", "-", stdin=asset)
        err = self.assert_fails(clitest.BAD_ARGS, "glintref", "render", "-", "-o", self.path("r.exr"), stdin=b"{}")
        self.assertIn("standard input", err)
        self.assert_fails(clitest.BAD_ARGS, "glintbake", "bake", "-", stdin=b"{}")

    def test_containers_and_images_refuse_stdout(self):
        m = self.mapgen("beckmann", "m.png", "--size", "16")
        err = self.assert_fails(clitest.BAD_ARGS, "ndfgen", m, "-o", "-", *SMALL)
        self.assertIn("standard output", err)
        self.assertFalse(os.path.exists("-"))
        err = self.assert_fails(clitest.BAD_ARGS, "mapgen", "flat", "-o", "-", "--size", "8")
        self.assertIn("standard output", err)

    def test_header_to_stdout(self):
        out, _ = self.run_ok("ltcfit", "table", "--size", "4", "--samples", "8", "-o", self.path("t.gbk"),
                             "--header", "-", "--quiet")
        self.assertIn("{", out)
        self.assertTrue(os.path.exists(self.path("t.gbk")))


class Warnings(ToolTestCase):
    def test_quiet_keeps_warnings_and_qq_hides_them(self):
        m = write_short_normals(self.path("short.pfm"))
        _, err = self.run_ok("ndfgen", m, "-o", self.path("a.gbk"), *SMALL, "--quiet")
        self.assertIn("ndfgen: warning: ", err)
        _, err = self.run_ok("ndfgen", m, "-o", self.path("b.gbk"), *SMALL, "-qq")
        self.assertEqual(err, "")

    def test_strict_fails_on_warnings_and_removes_outputs(self):
        m = write_short_normals(self.path("short.pfm"))
        out = self.path("s.gbk")
        code, _, err = clitest.run("ndfgen", m, "-o", out, *SMALL, "--quiet", "--strict")
        self.assertEqual(code, STRICT_WARNINGS, err)
        self.assertIn("--strict", err)
        self.assertFalse(os.path.exists(out))
        # Without warnings --strict changes nothing.
        clean = self.mapgen("beckmann", "clean.png", "--size", "16")
        self.run_ok("ndfgen", clean, "-o", self.path("c.gbk"), *SMALL, "--quiet", "--strict")


if __name__ == "__main__":
    unittest.main()
