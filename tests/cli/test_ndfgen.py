# SPDX-License-Identifier: Apache-2.0
"""ndfgen: the footprint pyramid of NDF images. Schema-valid --json, the container it writes, the
documented exit codes for bad input with nothing left behind, and byte-identical output for
every thread count."""

import json
import os
import struct

import clitest
from clitest import ToolTestCase, run

SMALL = ["--ndf-res", "16", "--stride", "8", "--sigma0", "4", "--quiet"]


def write_pfm(path, width, height, kind, values):
    """Portable float map: kind 'PF' (3 channels) or 'Pf' (1 channel), little-endian, bottom row first."""
    with open(path, "wb") as f:
        f.write(("%s\n%d %d\n-1.0\n" % (kind, width, height)).encode())
        f.write(struct.pack("<%df" % len(values), *values))


class NdfGen(ToolTestCase):
    def test_json_report_matches_schema_and_container(self):
        m = self.mapgen("beckmann", "m.png", "--size", "32", "--seed", "3")
        out = self.path("m.gbk")
        doc = self.run_json("ndfgen", m, "-o", out, *SMALL, schema="ndfgen.schema.json")
        self.assertTrue(os.path.exists(out))
        self.assertEqual(doc["map"], {"width": 32, "height": 32, "wrap": "repeat"})
        levels = doc["levels"]
        self.assertGreaterEqual(len(levels), 1)
        # Level l: stride and sigma double; the centre grid covers the map.
        for l in levels:
            self.assertAlmostEqual(l["sigma"], 4.0 * 2 ** l["level"])
            self.assertAlmostEqual(l["stride"][0] * l["grid"][0], 32.0)
            self.assertAlmostEqual(l["first_centre"][0], l["stride"][0] / 2)
        self.assertEqual(levels[0]["grid"], [4, 4])
        self.assertEqual(doc["images"], sum(l["images"] for l in levels))
        self.assertEqual(doc["file_bytes"], os.path.getsize(out))
        # The container's metadata and sections, through glintinfo when it is built.
        if os.path.exists(clitest.tool_path("glintinfo")):
            code, info, err = run("glintinfo", "info", out, "--json")
            self.assertEqual(code, 0, err)
            self.assertIn("ndf-pyramid", info)

    def test_explicit_level_count(self):
        m = self.mapgen("flakes", "f.png", "--size", "32")
        doc = self.run_json("ndfgen", m, "-o", self.path("f.gbk"), *SMALL, "--levels", "4",
                            schema="ndfgen.schema.json")
        self.assertEqual(len(doc["levels"]), 4)
        self.assertEqual(doc["stop_reason"], "levels")
        self.assertEqual(doc["levels"][3]["grid"], [1, 1])

    def test_identical_bytes_for_any_thread_count(self):
        m = self.mapgen("scratches", "s.png", "--size", "48")
        a, b, c = self.path("a.gbk"), self.path("b.gbk"), self.path("c.gbk")
        self.run_ok("ndfgen", m, "-o", a, *SMALL, "-j", "1")
        self.run_ok("ndfgen", m, "-o", b, *SMALL, "-j", "2")
        self.run_ok("ndfgen", m, "-o", c, *SMALL, "-j", "2")
        self.assertEqual(clitest.file_hash(a), clitest.file_hash(b))
        self.assertEqual(clitest.file_hash(b), clitest.file_hash(c))

    def test_bad_input_files(self):
        out = self.path("out.gbk")
        empty = self.path("empty.png")
        open(empty, "wb").close()
        self.assert_fails(clitest.INVALID, "ndfgen", empty, "-o", out, *SMALL, outputs=[out])
        nan = self.path("nan.pfm")
        write_pfm(nan, 4, 4, "PF", [0.0, 0.0, 1.0] * 15 + [float("nan"), 0.0, 1.0])
        self.assert_fails(clitest.INVALID, "ndfgen", nan, "-o", out, *SMALL, outputs=[out])
        one = self.path("one.pfm")
        write_pfm(one, 1, 1, "PF", [0.5, 0.5, 1.0])
        err = self.assert_fails(clitest.INVALID, "ndfgen", one, "-o", out, *SMALL, outputs=[out])
        self.assertIn("1x1", err)
        gray = self.path("gray.pfm")
        write_pfm(gray, 4, 4, "Pf", [0.5] * 16)
        self.assert_fails(clitest.INVALID, "ndfgen", gray, "-o", out, *SMALL, outputs=[out])
        huge = self.path("huge.pfm")
        with open(huge, "wb") as f:
            f.write(b"PF\n100000000 100000000\n-1.0\n" + b"\0" * 64)
        self.assert_fails(clitest.INVALID, "ndfgen", huge, "-o", out, *SMALL, outputs=[out])
        self.assert_fails(clitest.IO, "ndfgen", self.path("missing.png"), "-o", out, *SMALL, outputs=[out])

    def test_footprint_truncation(self):
        # Recorded in the parameters (3.5 by default); a wider cut keeps more flakes in each image.
        m = self.mapgen("beckmann", "m.png", "--size", "32", "--seed", "3")
        a, b = self.path("a.gbk"), self.path("b.gbk")
        doc_a = self.run_json("ndfgen", m, "-o", a, *SMALL, schema="ndfgen.schema.json")
        doc_b = self.run_json("ndfgen", m, "-o", b, *SMALL, "--footprint-truncation", "4",
                              schema="ndfgen.schema.json")
        self.assertEqual(doc_a["parameters"]["footprint_truncation"], 3.5)
        self.assertEqual(doc_b["parameters"]["footprint_truncation"], 4.0)
        self.assertNotEqual(clitest.file_hash(a), clitest.file_hash(b))

    def test_bad_arguments(self):
        m = self.mapgen("flat", "flat.png", "--size", "16")
        out = self.path("o.gbk")
        for args in (["--stride", "0"], ["--ndf-res", "1"], ["--levels", "zero"], ["--sigma-r", "-1"],
                     ["--rate", "99"], ["--converge-mse", "0"], ["--footprint-truncation", "0.5"],
                     ["--footprint-truncation", "11"], ["--footprint-truncation", "nan"]):
            self.assert_fails(clitest.BAD_ARGS, "ndfgen", m, "-o", out, "--quiet", *args, outputs=[out])

    def test_unwritable_output(self):
        m = self.mapgen("flat", "flat.png", "--size", "16")
        self.assert_fails(clitest.IO, "ndfgen", m, "-o", self.path("no/such/dir/o.gbk"), *SMALL)

    def test_depfile(self):
        m = self.mapgen("flat", "flat.png", "--size", "16")
        out, dep = self.path("o.gbk"), self.path("o.d")
        self.run_ok("ndfgen", m, "-o", out, *SMALL, "--depfile", dep)
        with open(dep) as f:
            text = f.read()
        self.assertIn("o.gbk", text)
        self.assertIn("flat.png", text)


if __name__ == "__main__":
    clitest.main()
