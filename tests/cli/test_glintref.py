# SPDX-License-Identifier: Apache-2.0
"""glintref: the reference P-NDF evaluator. Schema-valid --json for ndf, image and sample; the flat
map's analytic Gaussian; images consistent with point values and byte-identical for every thread
count; seeded samples; the documented exit codes for bad files and arguments, with nothing left
behind."""

import csv
import json
import math
import os
import struct
import zlib

import clitest
from clitest import ToolTestCase, run

AT = ["--at", "8.3,7.6", "--sigma", "2"]


def write_png_header(path, width, height):
    """A PNG whose IHDR claims width x height 8-bit RGB pixels, followed by a tiny IDAT and IEND:
    a reader must refuse it from the header, before allocating the image."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 64)) +
                chunk(b"IEND", b""))


class GlintRef(ToolTestCase):
    def setUp(self):
        super().setUp()
        self.map = self.mapgen("beckmann", "m.png", "--size", "16", "--seed", "4")

    def test_ndf_json_report(self):
        doc = self.run_json("glintref", "ndf", self.map, *AT, "--s", "0.05,-0.02", schema="glintref-ndf.schema.json")
        self.assertEqual(doc["command"], "ndf")
        self.assertEqual(doc["map"], {"name": "m.png", "width": 16, "height": 16, "wrap": "repeat"})
        self.assertEqual(doc["footprint"], {"x": 8.3, "y": 7.6, "sigma": 2.0})
        self.assertEqual(doc["s"], [0.05, -0.02])
        self.assertEqual(doc["rate"], 1)
        self.assertEqual(doc["sigma_r"], 0.005)
        self.assertGreater(doc["lobes"], 100)
        # A repeating map: the footprint's flakes carry unit mass (truncation loses ~1e-8).
        self.assertAlmostEqual(doc["total_weight"], 1.0, delta=1e-6)
        # Without --json: the value alone, with full precision.
        out, _ = self.run_ok("glintref", "ndf", self.map, *AT, "--s", "0.05,-0.02")
        self.assertEqual(float(out.strip()), doc["value"])

    def test_schemas_are_strict(self):
        import jsonschema
        doc = self.run_json("glintref", "sample", self.map, *AT, "--count", "2", schema="glintref-sample.schema.json")
        for mutate in (lambda d: d.update(extra=1), lambda d: d.pop("total_weight"),
                       lambda d: d["ingest"].pop("hash"), lambda d: d["map"].update(wrap="mirror"),
                       lambda d: d.update(output={"name": "s.csv", "format": "csv"}),
                       lambda d: d.update(samples=[[0.1]]), lambda d: d["footprint"].update(sigma=0)):
            bad = json.loads(json.dumps(doc))
            mutate(bad)
            with self.assertRaises(jsonschema.ValidationError):
                clitest.validate(bad, "glintref-sample.schema.json")

    def test_flat_map_is_the_intrinsic_gaussian(self):
        # mapgen writes signed float EXR; a flat map has no negative value, so say it is signed.
        flat = self.mapgen("flat", "flat.exr", "--size", "8")
        for sigma_r in (0.005, 0.02):
            doc = self.run_json("glintref", "ndf", flat, "--encoding", "snorm", "--at", "3,5", "--sigma", "2",
                                "--sigma-r", str(sigma_r), "--s", "0,0", schema="glintref-ndf.schema.json")
            expected = 1.0 / (2.0 * math.pi * sigma_r * sigma_r)
            self.assertLess(abs(doc["value"] - expected) / expected, 1e-6, doc["value"])
            # One standard deviation away along x: exp(-1/2) of the peak.
            doc = self.run_json("glintref", "ndf", flat, "--encoding", "snorm", "--at", "3,5", "--sigma", "2",
                                "--sigma-r", str(sigma_r), "--s", "%r,0" % sigma_r)
            self.assertLess(abs(doc["value"] - expected * math.exp(-0.5)) / expected, 1e-6)

    def test_image_json_and_consistency_with_ndf(self):
        out = self.path("ndf.exr")
        doc = self.run_json("glintref", "image", self.map, *AT, "--res", "32", "--sigma-r", "0.02", "-o", out,
                            schema="glintref-image.schema.json")
        self.assertTrue(os.path.getsize(out) > 0)
        self.assertEqual(doc["res"], 32)
        self.assertEqual(doc["output"], {"name": "ndf.exr", "format": "exr", "scale": 1.0})
        point = self.run_json("glintref", "ndf", self.map, *AT, "--sigma-r", "0.02", "--s", "0,0")
        # Bins hold exact averages: the image integrates to the total weight (slopes stay inside
        # the unit disk on this map), and the largest bin average is at most the peak density.
        self.assertAlmostEqual(doc["integral"], point["total_weight"], delta=1e-6)
        self.assertEqual(doc["lobes"], point["lobes"])
        self.assertGreater(doc["max"], 0.0)
        png = self.path("view.png")
        doc = self.run_json("glintref", "image", self.map, *AT, "--res", "16", "-o", png,
                            schema="glintref-image.schema.json")
        self.assertEqual(doc["output"]["format"], "png")
        self.assertAlmostEqual(doc["output"]["scale"] * doc["max"], 1.0, places=12)
        self.assertTrue(os.path.exists(png))
        # --preview: the same PNG beside the EXR, from one evaluation.
        both = self.path("both.png")
        doc = self.run_json("glintref", "image", self.map, *AT, "--res", "16", "-o", self.path("both.exr"),
                            "--preview", both, schema="glintref-image.schema.json")
        self.assertEqual(doc["preview"]["name"], "both.png")
        with open(png, "rb") as f, open(both, "rb") as g:
            self.assertEqual(f.read(), g.read())
        self.assert_fails(clitest.BAD_ARGS, "glintref", "image", self.map, *AT, "-o", self.path("n.exr"), "--preview",
                          self.path("n.jpg"), outputs=[self.path("n.exr")])

    def test_image_identical_bytes_for_any_thread_count(self):
        a, b, c = self.path("a.exr"), self.path("b.exr"), self.path("c.exr")
        args = ["image", self.map, "--at", "3.2,14.9", "--sigma", "3", "--res", "64", "--quiet"]
        self.run_ok("glintref", *args, "-o", a, "-j", "1")
        self.run_ok("glintref", *args, "-o", b, "-j", "2")
        self.run_ok("glintref", *args, "-o", c, "-j", "2")
        self.assertEqual(clitest.file_hash(a), clitest.file_hash(b))
        self.assertEqual(clitest.file_hash(b), clitest.file_hash(c))

    def test_sample_json_csv_and_seeds(self):
        doc = self.run_json("glintref", "sample", self.map, *AT, "--count", "50", "--seed", "9",
                            schema="glintref-sample.schema.json")
        samples = doc["samples"]
        self.assertEqual(len(samples), 50)
        self.assertEqual(doc["count"], 50)
        self.assertEqual(doc["seed"], 9)
        for k in range(2):
            self.assertAlmostEqual(doc["mean"][k], sum(s[k] for s in samples) / 50, places=12)
        # The same seed gives the same samples, in the CSV file too; another seed differs.
        csv_path = self.path("s.csv")
        filed = self.run_json("glintref", "sample", self.map, *AT, "--count", "50", "--seed", "9", "-o", csv_path,
                              schema="glintref-sample.schema.json")
        self.assertEqual(filed["output"], {"name": "s.csv", "format": "csv"})
        self.assertNotIn("samples", filed)
        with open(csv_path) as f:
            rows = list(csv.reader(f))
        self.assertEqual(rows[0], ["sx", "sy"])
        self.assertEqual([[float(v) for v in r] for r in rows[1:]], samples)
        other = self.run_json("glintref", "sample", self.map, *AT, "--count", "50", "--seed", "10")
        self.assertNotEqual(other["samples"], samples)
        # CSV on stdout without --json.
        out, _ = self.run_ok("glintref", "sample", self.map, *AT, "--count", "3", "--seed", "9")
        lines = out.strip().splitlines()
        self.assertEqual(lines[0], "sx,sy")
        self.assertEqual([[float(v) for v in l.split(",")] for l in lines[1:]], samples[:3])

    def test_bad_input_files(self):
        out = self.path("out.exr")
        missing = self.path("missing.png")
        empty = self.path("empty.png")
        open(empty, "wb").close()
        garbage = self.path("garbage.png")
        with open(garbage, "wb") as f:
            f.write(bytes((i * 37 + 11) % 256 for i in range(4096)))
        huge = self.path("huge.png")
        write_png_header(huge, 100000, 100000)
        for command, extra, output in (("image", ["-o", out], out), ("ndf", ["--s", "0,0"], None),
                                       ("sample", ["--count", "5", "-o", self.path("s.csv")], self.path("s.csv"))):
            outputs = [output] if output else []
            self.assert_fails(clitest.IO, "glintref", command, missing, *AT, *extra, outputs=outputs)
            self.assert_fails(clitest.INVALID, "glintref", command, empty, *AT, *extra, outputs=outputs)
        self.assert_fails(clitest.INVALID, "glintref", "image", garbage, *AT, "-o", out, outputs=[out])
        err = self.assert_fails(clitest.INVALID, "glintref", "image", huge, *AT, "-o", out, outputs=[out])
        self.assertIn("huge.png", err)

    def test_bad_arguments(self):
        out, csv_path = self.path("o.exr"), self.path("o.csv")
        image = ["image", self.map, "--at", "4,4", "-o", out]
        for args in (["--sigma", "0"], ["--sigma", "-2"], ["--sigma", "nan"], ["--sigma", "abc"],
                     ["--sigma", "1e6"], ["--sigma", "2", "--res", "0"], ["--sigma", "2", "--res", "5000"],
                     ["--sigma", "2", "--res", "x"], ["--sigma", "2", "--sigma-r", "0"],
                     ["--sigma", "2", "--rate", "17"]):
            self.assert_fails(clitest.BAD_ARGS, "glintref", *image, *args, outputs=[out])
        sample = ["sample", self.map, *AT, "-o", csv_path]
        for args in (["--count", "0"], ["--count", "-3"], ["--count", "100000001"], ["--count", "many"]):
            self.assert_fails(clitest.BAD_ARGS, "glintref", *sample, *args, outputs=[csv_path])
        for at in ("4", "4,x", "inf,2"):
            self.assert_fails(clitest.BAD_ARGS, "glintref", "ndf", self.map, "--at", at, "--sigma", "2", "--s", "0,0")
        self.assert_fails(clitest.BAD_ARGS, "glintref", "ndf", self.map, *AT, "--s", "0")
        self.assert_fails(clitest.BAD_ARGS, "glintref", "image", self.map, *AT, "-o", self.path("o.tga"))
        # A clamped footprint that sees no flake has nothing to sample.
        self.assert_fails(clitest.BAD_ARGS, "glintref", "sample", self.map, "--wrap", "clamp", "--at", "-500,-500",
                          "--sigma", "1", "--count", "5", "-o", csv_path, outputs=[csv_path])
        # Arguments are checked before the file is read.
        self.assert_fails(clitest.BAD_ARGS, "glintref", "image", self.path("missing.png"), "--at", "4,4",
                          "--sigma", "0", "-o", out, outputs=[out])

    def test_unwritable_output_and_depfile(self):
        self.assert_fails(clitest.IO, "glintref", "image", self.map, *AT, "-o", self.path("no/such/dir/o.exr"))
        out, dep = self.path("o.exr"), self.path("o.d")
        self.run_ok("glintref", "image", self.map, *AT, "--res", "8", "-o", out, "--depfile", dep, "--quiet")
        with open(dep) as f:
            text = f.read()
        self.assertIn("o.exr", text)
        self.assertIn("m.png", text)


if __name__ == "__main__":
    clitest.main()
