# SPDX-License-Identifier: Apache-2.0
"""tinyexample: a schema-valid --json summary, assets glintinfo validates and glintquery reads,
byte-identical output for -j1 and -j2, and one-line errors with documented exit codes and nothing
left behind for bad examples and options."""

import clitest
from clitest import ToolTestCase


class TinyExample(ToolTestCase):
    def setUp(self):
        super().setUp()
        self.map = self.mapgen("beckmann", "b.exr", "--size", "64", "--alpha", "0.2", "--cell", "1.5")

    def bake(self, name, *args, json=False, **kw):
        out = self.path(name)
        cmd = [self.map, "--crop", "8,16,16", "-o", out, "--ndf-res", "32", "--quiet", *args]
        if json:
            return out, self.run_json("tinyexample", *cmd, schema="tinyexample.schema.json", **kw)
        self.run_ok("tinyexample", *cmd, **kw)
        return out, None

    def test_tiled_json_validate_and_query(self):
        out, doc = self.bake("t.gbk", json=True)
        self.assertEqual(doc["asset"]["type"], "tiled")
        self.assertEqual(doc["asset"]["example_size"], 16)
        self.assertEqual(doc["tiles"], 85)
        self.assertEqual(doc["raw_bytes"], 85 * 32 * 32 * 4)
        self.assertTrue(doc["flakes"])
        self.assertLess(doc["file_bytes"], doc["raw_bytes"])
        self.run_ok("glintinfo", "validate", out)
        info = self.run_json("glintinfo", "info", out)
        self.assertEqual(info["asset_kind"], "tiny-example")
        q = self.run_json("glintquery", "point", out, "--at", "1000,-70", "--sigma", "40", "--s", "0.05,0.0")
        self.assertGreaterEqual(q["value"], 0.0)

    def test_stochastic_json(self):
        out, doc = self.bake("s.gbk", "--type", "stochastic", "--rotate-range", "0,360", "--scale-range", "0.8,1.2",
                             "--density", "0.3", "--seed", "7", json=True)
        a = doc["asset"]
        self.assertEqual(a["type"], "stochastic")
        self.assertAlmostEqual(a["covered_fraction"], 0.3, places=9)
        self.assertFalse(doc["flakes"])
        self.run_ok("glintinfo", "validate", out)

    def test_deterministic_for_thread_counts(self):
        a, _ = self.bake("a.gbk", "--rotate", "90", "-j", "1")
        b, _ = self.bake("b.gbk", "--rotate", "90", "-j", "2")
        self.assertEqual(clitest.file_hash(a), clitest.file_hash(b))

    def test_bad_examples_and_options(self):
        out = self.path("bad.gbk")
        # Not a power of two, too large, not square.
        odd = self.mapgen("beckmann", "odd.exr", "--size", "24")
        self.assert_fails(1, "tinyexample", odd, "-o", out, outputs=[out])
        big = self.mapgen("flat", "big.exr", "--size", "512")
        self.assert_fails(1, "tinyexample", big, "-o", out, outputs=[out])
        self.assert_fails(1, "tinyexample", self.map, "--crop", "0,0,48", "-o", out, outputs=[out])
        base = [self.map, "--crop", "0,0,16", "-o", out]
        for bad in (["--type", "wang"], ["--ndf-res", "1"], ["--ndf-res", "4096"], ["--sigma-r", "nan"],
                    ["--sigma-r", "0"], ["--scale-range", "2,1"], ["--scale-range", "0.01,1"],
                    ["--type", "stochastic", "--density", "0"], ["--type", "stochastic", "--density", "1.5"],
                    ["--type", "stochastic", "--rotate-range", "0,45", "--density", "0.9"],
                    ["--rotate-range", "0,90"], ["--shear", "1,1"], ["--shear", "x"], ["--crop", "60,60,16"]):
            self.assert_fails(1, "tinyexample", *base, *bad, outputs=[out])
        self.assert_fails(5, "tinyexample", *base, "--layout", "noise.exr", outputs=[out])
        self.assert_fails(4, "tinyexample", self.map, "--ndf-res", "1024", "--max-memory", "1M", "-o", out,
                          outputs=[out])
        self.assert_fails(2, "tinyexample", self.path("missing.exr"), "-o", out, outputs=[out])
        # A file that is no image is invalid input.
        junk = self.write("junk.exr", b"not an image")
        self.assert_fails(3, "tinyexample", junk, "-o", out, outputs=[out])

    def test_corrupt_asset_is_refused(self):
        out, _ = self.bake("c.gbk")
        data = bytearray(open(out, "rb").read())
        data[200] ^= 0xFF
        bad = self.write("corrupt.gbk", bytes(data))
        code, _, _ = clitest.run("glintinfo", "validate", bad)
        self.assertNotEqual(code, 0)


if __name__ == "__main__":
    clitest.main()
