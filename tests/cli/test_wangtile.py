# SPDX-License-Identifier: Apache-2.0
"""wangtile: a small tile set baked from a generated example (schema-valid --json, an asset
glintinfo validates and glintquery answers anywhere on the plane, an atlas image, seams no worse
than straight cuts, byte-identical output for -j1 and -j2) and one-line errors with documented exit
codes that leave nothing behind."""

import os

import clitest
from clitest import ToolTestCase

SMALL = ["--tile-size", "16", "--ndf-res", "16", "--block", "8", "--sigma0", "1", "--stride", "2", "--rank", "4",
         "--max-iters", "20", "--quiet"]


class WangTile(ToolTestCase):
    def example(self):
        return self.mapgen("beckmann", "ex.png", "--size", "48", "--alpha", "0.3")

    def test_bake_query_validate_deterministic(self):
        ex = self.example()
        out, atlas = self.path("w.gbk"), self.path("atlas.exr")
        doc = self.run_json("wangtile", ex, "-o", out, "--atlas", atlas, *SMALL, "-j2", schema="wangtile.schema.json")
        self.assertEqual(doc["tile_count"], 16)
        self.assertEqual(doc["tile_size"], 16)
        self.assertLessEqual(doc["seam"]["mean_degrees"], doc["plain_seam"]["mean_degrees"])
        self.assertGreater(doc["sizes"]["map_16k_estimate_bytes"], doc["sizes"]["file_bytes"])
        self.assertTrue(os.path.exists(atlas))
        self.run_ok("glintinfo", "validate", out)
        info = self.run_json("glintinfo", "info", out)
        self.assertEqual(info["asset_kind"], "wang-tiles")
        for at in ("8,8", "-1000.5,123456.25", "16,16"):
            for sigma in ("0.5", "3"):
                q = self.run_json("glintquery", "point", out, "--at", at, "--sigma", sigma, "--s", "0.05,0.02",
                                  schema="glintquery-point.schema.json")
                self.assertGreaterEqual(q["value"], 0.0)
        self.run_json("glintquery", "image", out, "--at", "8,8", "--sigma", "3", "-o", self.path("w.exr"),
                      schema="glintquery-image.schema.json")
        out1 = self.path("w1.gbk")
        self.run_ok("wangtile", ex, "-o", out1, *SMALL, "-j1")
        self.assertEqual(clitest.file_hash(out), clitest.file_hash(out1))

    def test_materialise_a_grid_region(self):
        """glintquery materialise writes the implicit grid's texels as a normal map: the reference
        evaluator on it agrees with the asset (uncompressed) inside the region, and bad requests fail
        with one line and nothing left behind."""
        ex = self.example()
        out = self.path("w.gbk")
        self.run_ok("wangtile", ex, "-o", out, "--uncompressed", *SMALL)
        region = self.path("region.exr")
        doc = self.run_json("glintquery", "materialise", out, "--cells", "-2,3,4,4", "-o", region,
                            schema="glintquery-materialise.schema.json")
        self.assertEqual(doc["size"], [64, 64])
        # Cell (-2, 3) is texel (0, 0) of the region: texel (24.5, 40.5) of it is (-7.5, 88.5) on the plane.
        for s in ("0.05,0.02", "-0.1,0.04"):
            ref = self.run_json("glintref", "ndf", region, "--at", "24.5,40.5", "--sigma", "1", "--s", s)
            q = self.run_json("glintquery", "point", out, "--at", "-7.5,88.5", "--sigma", "1", "--s", s)
            self.assertAlmostEqual(q["value"], ref["value"], delta=1e-3 * max(1.0, ref["value"]))
        bad = self.path("bad.exr")
        for cells in ("0,0,0,4", "0,0,4", "a,b,c,d", "0,0,2000,2000"):
            self.assert_fails(1, "glintquery", "materialise", out, "--cells", cells, "-o", bad, outputs=[bad])
        self.assert_fails(1, "glintquery", "materialise", out, "--cells", "0,0,1,1", "-o", self.path("x.png"),
                          outputs=[self.path("x.png")])
        self.assert_fails(3, "glintquery", "materialise", ex, "--cells", "0,0,1,1", "-o", bad, outputs=[bad])
        pyramid = self.path("p.gbk")
        self.run_ok("ndfgen", ex, "-o", pyramid, "--ndf-res", "16", "--quiet")
        self.assert_fails(5, "glintquery", "materialise", pyramid, "--cells", "0,0,1,1", "-o", bad, outputs=[bad])

    def test_uncompressed_and_plain_cut(self):
        ex = self.example()
        out = self.path("u.gbk")
        doc = self.run_json("wangtile", ex, "-o", out, "--uncompressed", "--plain-cut", *SMALL,
                            schema="wangtile.schema.json")
        self.assertIsNone(doc["relative_error"])
        self.assertEqual(doc["seam"], doc["plain_seam"])
        self.run_ok("glintinfo", "validate", out)

    def test_bad_input(self):
        ex = self.example()
        out = self.path("bad.gbk")
        for bad in (["--colors", "5"], ["--colors", "1"], ["--tile-size", "4"], ["--sigma0", "100"], ["--block", "5"],
                    ["--atlas", self.path("noext")]):
            self.assert_fails(clitest.BAD_ARGS, "wangtile", ex, "-o", out, *SMALL, *bad, outputs=[out])
        self.assert_fails(clitest.IO, "wangtile", self.path("missing.png"), "-o", out, *SMALL, outputs=[out])
        # An example smaller than one tile.
        self.assert_fails(clitest.INVALID, "wangtile", ex, "-o", out, *SMALL[2:], "--tile-size", "64",
                          outputs=[out])
        garbage = self.write("g.png", b"not an image")
        self.assert_fails(clitest.INVALID, "wangtile", garbage, "-o", out, *SMALL, outputs=[out])


if __name__ == "__main__":
    clitest.main()
