# SPDX-License-Identifier: Apache-2.0
"""mapgen: every kind writes a readable map, --json follows its schema, output bytes are
reproducible (two runs, -j1 vs -j2), and bad arguments or unwritable outputs fail cleanly."""

import os

import clitest
from clitest import ToolTestCase, run

KINDS = ["flat", "beckmann", "brushed", "scratches", "flakes"]


class Mapgen(ToolTestCase):
    def test_every_kind_writes_png(self):
        # (EXR output of every kind is covered by the --json test.)
        for kind in KINDS:
            out = self.mapgen(kind, f"{kind}.png", "--size", "32", "--seed", "3")
            with open(out, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", out)
        self.assertEqual(sorted(f for f in os.listdir(self.tmp) if ".tmp" in f), [])

    def test_json_matches_schema_and_statistics(self):
        for kind in KINDS:
            doc = self.run_json("mapgen", kind, "-o", self.path(f"{kind}.exr"), "--size", "64", "--seed", "7",
                                schema="mapgen.schema.json")
            self.assertEqual(doc["kind"], kind)
            self.assertEqual(doc["size"], 64)
            self.assertEqual(doc["seed"], 7)
            self.assertEqual(doc["encoding"], "float")
        flat = self.run_json("mapgen", "flat", "-o", self.path("f.png"), "--size", "8",
                             schema="mapgen.schema.json")
        self.assertEqual(flat["statistics"]["mean_normal"], [0.0, 0.0, 1.0])
        self.assertEqual(flat["encoding"], "unorm16")
        beck = self.run_json("mapgen", "beckmann", "-o", self.path("b.exr"), "--size", "128", "--alpha", "0.4",
                             schema="mapgen.schema.json")
        self.assertEqual(beck["parameters"], {"alpha": 0.4, "cell": 3.0})
        for s in beck["statistics"]["slope_std"]:
            self.assertAlmostEqual(s, 0.4 / 2 ** 0.5, delta=0.15 * 0.4 / 2 ** 0.5)

    def test_reproducible_bytes(self):
        # Two runs with different thread counts must agree byte for byte (each tool start costs
        # about half a second, so every kind is checked in EXR and two kinds also in PNG).
        outputs = [(kind, "exr") for kind in KINDS] + [("beckmann", "png"), ("flakes", "png")]
        for kind, ext in outputs:
            a = self.mapgen(kind, f"a-{kind}.{ext}", "--size", "48", "--seed", "11", "-j", "1")
            b = self.mapgen(kind, f"b-{kind}.{ext}", "--size", "48", "--seed", "11", "-j", "2")
            self.assertEqual(clitest.file_hash(a), clitest.file_hash(b), f"{kind}.{ext}: -j1 vs -j2")
        d = self.mapgen("beckmann", "d.exr", "--size", "48", "--seed", "12")
        self.assertNotEqual(clitest.file_hash(self.path("a-beckmann.exr")), clitest.file_hash(d))

    def test_bad_arguments(self):
        out = self.path("x.exr")
        cases = [
            ("bogus", "-o", out),
            ("flat", "-o", out, "--size", "0"),
            ("flat", "-o", out, "--size", "20000"),
            ("flat", "-o", out, "--size", "64", "--max-size", "32"),
            ("beckmann", "-o", out, "--alpha", "-1"),
            ("brushed", "-o", out, "--alpha-x", "0"),
            ("flakes", "-o", out, "--cone", "120"),
            ("scratches", "-o", out, "--width", "0"),
            ("flat", "-o", self.path("x.bmpx")),
            ("flat", "-o", self.path("x.png"), "--png-bits", "12"),
            ("flat",),
        ]
        for args in cases:
            err = self.assert_fails(clitest.BAD_ARGS, "mapgen", *args, outputs=[out, self.path("x.png")])
            self.assertTrue(err.startswith("mapgen: error: "), err)
            if args[0] == "bogus":
                self.assertIn("beckmann", err)  # the error lists the valid kinds

    def test_unwritable_output_is_io_error(self):
        missing = self.path("no/such/dir/out.exr")
        self.assert_fails(clitest.IO, "mapgen", "flat", "-o", missing, "--size", "8", outputs=[missing])
        os.chmod(self.tmp, 0o500)
        try:
            if os.access(self.tmp, os.W_OK):
                return  # running as root: permissions are not enforced
            out = self.path("denied.png")
            code, _, err = run("mapgen", "flat", "-o", out, "--size", "8")
            self.assertEqual(code, clitest.IO, err)
            self.assertEqual(len(err.strip().splitlines()), 1, err)
            self.assertFalse(os.path.exists(out))
        finally:
            os.chmod(self.tmp, 0o700)

    def test_depfile_lists_the_target(self):
        out = self.path("m.exr")
        dep = self.path("m.d")
        self.run_ok("mapgen", "flakes", "-o", out, "--size", "16", "--depfile", dep, "--quiet")
        with open(dep) as f:
            text = f.read()
        self.assertTrue(text.startswith(out.replace(" ", "\\ ") + ":"), text)
        self.assertEqual(text.split(":", 1)[1].strip(), "")

    def test_png_is_readable_by_ingest_conventions(self):
        # 16-bit PNG stores (n+1)/2: a flat map is (0.5, 0.5, 1.0) everywhere.
        try:
            import OpenImageIO as oiio  # optional: only when the Python bindings are installed
        except ImportError:
            self.skipTest("OpenImageIO Python bindings not installed")
        out = self.mapgen("flat", "flat.png", "--size", "4")
        pixels = oiio.ImageBuf(out).get_pixels(oiio.FLOAT)
        self.assertAlmostEqual(float(pixels[0][0][0]), 32768 / 65535, places=5)
        self.assertAlmostEqual(float(pixels[0][0][2]), 1.0, places=5)


if __name__ == "__main__":
    clitest.main()
