# SPDX-License-Identifier: Apache-2.0
"""tinyexample: a schema-valid --json summary, assets glintinfo validates and glintquery reads,
byte-identical output for -j1 and -j2, and one-line errors with documented exit codes and nothing
left behind for bad examples and options."""

import os
import struct

import clitest
from clitest import ToolTestCase


def write_exr(path, width, height, channels):
    """A float32 scanline OpenEXR file, uncompressed: `channels` maps a name to width * height values
    (row-major). Written here so that the tests can store values no encoder would (NaN)."""
    names = sorted(channels)
    def attr(name, kind, data):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(data)) + data
    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for n in names) + b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (attr("channels", "chlist", chlist) + attr("compression", "compression", b"\0") +
              attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", box) +
              attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)) +
              attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)) +
              attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    start = 8 + len(header) + 8 * height
    line = 8 + 4 * width * len(names)
    offsets = struct.pack(f"<{height}Q", *[start + y * line for y in range(height)])
    rows = b"".join(struct.pack("<ii", y, line - 8) + b"".join(
        struct.pack(f"<{width}f", *channels[n][y * width:(y + 1) * width]) for n in names) for y in range(height))
    with open(path, "wb") as f:
        f.write(struct.pack("<ii", 20000630, 2) + header + offsets + rows)
    return path


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
        q = self.run_json("glintquery", "point", out, "--at", "1000,-70", "--sigma", "40", "--s", "0.05,0.0",
                          schema="glintquery-point.schema.json")
        self.assertGreaterEqual(q["value"], 0.0)
        self.run_json("glintquery", "image", out, "--at", "1000,-70", "--sigma", "40", "-o", self.path("t.exr"),
                      schema="glintquery-image.schema.json")
        # float16 tile images by default; --precision float32 keeps them whole, in a larger file.
        self.assertEqual(doc["precision"], "float16")
        out32, doc32 = self.bake("t32.gbk", "--precision", "float32", json=True)
        self.assertEqual(doc32["precision"], "float32")
        self.assertLess(doc["file_bytes"], doc32["file_bytes"])
        self.run_ok("glintinfo", "validate", out32)
        p16 = self.run_json("glintquery", "point", out, "--at", "30,7", "--sigma", "9", "--s", "0.05,0.0")
        p32 = self.run_json("glintquery", "point", out32, "--at", "30,7", "--sigma", "9", "--s", "0.05,0.0")
        self.assertAlmostEqual(p16["value"], p32["value"], delta=1e-3 * abs(p32["value"]) + 1e-6)
        err = self.assert_fails(1, "tinyexample", self.map, "--crop", "8,16,16", "-o", self.path("bad.gbk"), "--precision", "float8",
                                outputs=[self.path("bad.gbk")])
        self.assertIn("--precision", err)

    def test_stochastic_json(self):
        out, doc = self.bake("s.gbk", "--type", "stochastic", "--rotate-range", "0,360", "--scale-range", "0.8,1.2",
                             "--density", "0.3", "--seed", "7", json=True)
        a = doc["asset"]
        self.assertEqual(a["type"], "stochastic")
        self.assertAlmostEqual(a["covered_fraction"], 0.3, places=9)
        self.assertTrue(doc["flakes"])  # every placement: the plane's flakes
        self.assertEqual(doc["precision"], "float16")
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
        self.assert_fails(2, "tinyexample", *base, "--type", "stochastic", "--layout", self.path("noise.exr"),
                          outputs=[out])
        self.assert_fails(4, "tinyexample", self.map, "--ndf-res", "1024", "--max-memory", "1M", "-o", out,
                          outputs=[out])
        self.assert_fails(2, "tinyexample", self.path("missing.exr"), "-o", out, outputs=[out])
        # A file that is no image is invalid input.
        junk = self.write("junk.exr", b"not an image")
        self.assert_fails(3, "tinyexample", junk, "-o", out, outputs=[out])

    def test_materialise_the_plane(self):
        """glintquery materialise writes a region of the asset's plane as a normal map: on the tiled
        plane (identity and a 90-degree rotation) the reference evaluator on it equals the asset's
        exact flakes path, and a stochastic region's covered texels track --density."""
        for extra in ([], ["--rotate", "90"]):
            out, _ = self.bake("t.gbk", *extra)
            region = self.path("region.exr")
            doc = self.run_json("glintquery", "materialise", out, "--cells", "-1,2,2,2", "-o", region,
                                schema="glintquery-materialise.schema.json")
            self.assertEqual(doc["kind"], "tiny-example")
            self.assertEqual(doc["tile_size"], 16)
            self.assertEqual(doc["size"], [32, 32])
            self.assertEqual(doc["covered_fraction"], 1.0)
            # Texel (10.5, 21.5) of the region is (-5.5, 53.5) on the plane.
            for s in ("0.05,0.02", "-0.1,0.04", "0.0,-0.15"):
                ref = self.run_json("glintref", "ndf", region, "--at", "10.5,21.5", "--sigma", "1.5", "--s", s)
                q = self.run_json("glintquery", "point", out, "--at", "-5.5,53.5", "--sigma", "1.5", "--s", s)
                self.assertAlmostEqual(q["value"], ref["value"], delta=1e-3 * max(1.0, ref["value"]), msg=extra)
        out, doc = self.bake("s.gbk", "--type", "stochastic", "--rotate-range", "0,360", "--scale-range", "0.8,1.25",
                             "--density", "0.3", "--seed", "3", json=True)
        region = self.path("s.exr")
        m = self.run_json("glintquery", "materialise", out, "--cells", "-32,-32,64,64", "-o", region,
                          schema="glintquery-materialise.schema.json")
        self.assertAlmostEqual(m["covered_fraction"], 0.3, delta=0.03)
        bad = self.path("bad.exr")
        for cells in ("0,0,0,1", "0,0,2000,2000", "x"):
            self.assert_fails(1, "glintquery", "materialise", out, "--cells", cells, "-o", bad, outputs=[bad])

    def test_layout_image(self):
        """--layout: channel 0 the presence per cell, 1 the rotation, 2 the scale; the layout's cells
        decide where examples are, and bad layout images are refused with one line and no output."""
        def args(out, rotate="0,90"):
            return [self.map, "--crop", "8,16,16", "-o", out, "--ndf-res", "16", "--type", "stochastic",
                    "--rotate-range", rotate]
        out = self.path("l.gbk")
        w = h = 8
        checker = [float((x + y) % 2) for y in range(h) for x in range(w)]
        layout = write_exr(self.path("checker.exr"), w, h, {"Y": checker})
        doc = self.run_json("tinyexample", *args(out), "--layout", layout, schema="tinyexample.schema.json")
        self.assertTrue(doc["asset"]["layout"])
        self.run_ok("glintinfo", "validate", out)
        full = self.run_json("tinyexample", *args(self.path("f.gbk")), "--density", "0.2")["asset"]
        # Half the cells hold an example: half the covered fraction of a layout with every cell full.
        full_max = full["covered_fraction"] / full["occupancy"]
        self.assertAlmostEqual(doc["asset"]["covered_fraction"] / full_max, 0.5, places=9)
        self.assertEqual(doc["asset"]["occupancy"], 1.0)
        region = self.path("region.exr")
        m = self.run_json("glintquery", "materialise", out, "--cells", "0,0,64,64", "-o", region)
        self.assertAlmostEqual(m["covered_fraction"], doc["asset"]["covered_fraction"], delta=0.02)
        # Every second cell of the checker is empty: around its centre the materialised plane is flat
        # (the reference's NDF there is the flat lobe, 1 / (2 pi sigma_r^2) at s = 0).
        cell = doc["asset"]["cell_size"]
        flat = 1.0 / (2 * 3.141592653589793 * 0.005 ** 2)
        for (i, j), covered in (((0, 0), False), ((1, 0), True), ((3, 2), True), ((2, 2), False)):
            x, y = (i + 0.5) * cell, (j + 0.5) * cell
            q = self.run_json("glintref", "ndf", region, "--at", f"{x},{y}", "--sigma", "0.3", "--s", "0,0")
            if covered:
                self.assertLess(q["value"], 0.5 * flat, (i, j))
            else:
                self.assertAlmostEqual(q["value"] / flat, 1.0, delta=0.02, msg=(i, j))
        # --density scales the presences.
        half = self.run_json("tinyexample", *args(self.path("h.gbk")), "--layout", layout, "--density",
                             repr(doc["asset"]["covered_fraction"] / 2))["asset"]
        self.assertAlmostEqual(half["occupancy"], 0.5, places=9)
        # The rotation channel replaces the seed's: rotation 1 of the range 0,90 and rotation 0 of the range
        # 90,180 are both 90 degrees in every cell, the same plane.
        ones, zeros = [1.0] * (w * h), [0.0] * (w * h)
        maps = []
        for name, rotate, value in (("a", "0,90", ones), ("b", "90,180", zeros)):
            asset = self.path(name + ".gbk")
            image = write_exr(self.path(name + "_layout.exr"), w, h, {"R": ones, "G": value})
            self.run_ok("tinyexample", *args(asset, rotate), "--layout", image, "--quiet")
            maps.append(self.path(name + ".exr"))
            self.run_ok("glintquery", "materialise", asset, "--cells", "0,0,8,8", "-o", maps[-1], "--quiet")
        self.assertEqual(clitest.file_hash(maps[0]), clitest.file_hash(maps[1]))
        # And differs from the seed's rotations.
        seeded = self.path("seeded.exr")
        self.run_ok("tinyexample", *args(self.path("c.gbk")), "--layout", write_exr(self.path("c.exr"), w, h,
                                                                                    {"Y": ones}), "--quiet")
        self.run_ok("glintquery", "materialise", self.path("c.gbk"), "--cells", "0,0,8,8", "-o", seeded, "--quiet")
        self.assertNotEqual(clitest.file_hash(maps[0]), clitest.file_hash(seeded))
        # Bad layouts: too many channels, NaN, values outside [0, 1], an absurd size, no example at all;
        # the tiled type, a density the layout cannot reach, a missing file.
        os.remove(out)
        four = write_exr(self.path("four.exr"), 2, 2, {"R": [1.0] * 4, "G": [0.0] * 4, "B": [0.0] * 4, "A": [1.0] * 4})
        nan = write_exr(self.path("nan.exr"), 2, 2, {"Y": [1.0, float("nan"), 1.0, 1.0]})
        big = write_exr(self.path("big.exr"), 1, 1, {"Y": [2.0]})
        wide = write_exr(self.path("wide.exr"), 2048, 1, {"Y": [1.0] * 2048})
        zero = write_exr(self.path("zero.exr"), 2, 2, {"Y": [0.0] * 4})
        for bad, words in ((four, "4 channels"), (nan, "pixel 1,0"), (big, "outside [0, 1]"), (wide, "2048x1"),
                           (zero, "presence is 0")):
            err = self.assert_fails(3, "tinyexample", *args(out), "--layout", bad, outputs=[out])
            self.assertIn(words, err)
        self.assert_fails(1, "tinyexample", self.map, "--crop", "8,16,16", "-o", out, "--layout", layout,
                          outputs=[out])
        self.assert_fails(1, "tinyexample", *args(out), "--layout", layout, "--density", "0.9", outputs=[out])
        self.assert_fails(2, "tinyexample", *args(out), "--layout", self.path("none.exr"), outputs=[out])

    def test_overlapping_examples(self):
        """--overlap: examples overlap and the nearest centre owns each point, so densities above what
        disjoint cells allow are reached; the materialised plane's covered texels and the runtime's
        share of flat ground both track --density."""
        beck = self.mapgen("beckmann", "wide.exr", "--size", "32", "--alpha", "0.5", "--cell", "1.5")
        # The flat lobe's bin at s = (0.001, 0.001) (R = 128, sigma_r = 0.005): its mass over the bin's area.
        import math
        flat = (0.5 * math.erf(1 / 64 / 0.005 / math.sqrt(2))) ** 2 * 64 * 64
        disjoint = self.path("d.gbk")
        self.assert_fails(1, "tinyexample", beck, "--crop", "0,0,16", "-o", disjoint, "--type", "stochastic",
                          "--rotate-range", "0,360", "--density", "0.7", outputs=[disjoint])
        for density in (0.3, 0.7, 0.95):
            out = self.path(f"o{density}.gbk")
            doc = self.run_json("tinyexample", beck, "--crop", "0,0,16", "-o", out, "--type", "stochastic",
                                "--rotate-range", "0,360", "--scale-range", "0.8,1.25", "--density", repr(density),
                                "--seed", "9", "--overlap", schema="tinyexample.schema.json")
            a = doc["asset"]
            self.assertTrue(a["overlap"])
            # Exact up to one example's share of the sample points.
            self.assertAlmostEqual(a["covered_fraction"], density, delta=1e-3)
            self.assertLess(a["cell_size"], 16 * 1.25 * math.sqrt(2))
            self.run_ok("glintinfo", "validate", out)
            region = self.path("r.exr")
            m = self.run_json("glintquery", "materialise", out, "--cells", "-40,-40,80,80", "-o", region)
            self.assertAlmostEqual(m["covered_fraction"], density, delta=0.02, msg=density)
            # A wide footprint: its flat-ground share is 1 - the covered fraction.
            q = self.run_json("glintquery", "point", out, "--at", "300,-200", "--sigma", "60", "--s", "0.001,0.001")
            self.assertAlmostEqual(1.0 - q["value"] / flat, density, delta=0.04, msg=density)
        a = self.path("a.gbk")
        b = self.path("b.gbk")
        common = [beck, "--crop", "0,0,16", "--type", "stochastic", "--rotate-range", "0,360", "--density", "0.6",
                  "--overlap", "--ndf-res", "32", "--quiet"]
        self.run_ok("tinyexample", *common, "-o", a, "-j", "1")
        self.run_ok("tinyexample", *common, "-o", b, "-j", "2")
        self.assertEqual(clitest.file_hash(a), clitest.file_hash(b))
        self.assert_fails(1, "tinyexample", beck, "--crop", "0,0,16", "-o", disjoint, "--overlap",
                          outputs=[disjoint])

    def test_corrupt_asset_is_refused(self):
        out, _ = self.bake("c.gbk")
        data = bytearray(open(out, "rb").read())
        data[200] ^= 0xFF
        bad = self.write("corrupt.gbk", bytes(data))
        code, _, _ = clitest.run("glintinfo", "validate", bad)
        self.assertNotEqual(code, 0)


if __name__ == "__main__":
    clitest.main()
