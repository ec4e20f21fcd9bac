# SPDX-License-Identifier: Apache-2.0
"""scripts/fidelity.py: its splatted references of large footprints (one footprint baked by ndfgen
on a shifted copy of the map) are the images the exact reference evaluator gives, on axes that the
footprint is flat over, and on axes repeated over 2 and 6 periods."""

import os
import struct
import sys

import clitest

sys.path.insert(0, os.path.join(clitest.SOURCE_DIR, "scripts"))
import fidelity  # noqa: E402


class SplatReference(clitest.ToolTestCase):
    def test_splat_matches_the_reference_evaluator(self):
        square = self.mapgen("beckmann", "square.png", "--size", 32, "--seed", 5)
        # A 32 x 20 map (even sizes: footprint centres on whole texels).
        width, height, bpp, ihdr, rows = fidelity._read_png_rows(square)
        path = self.path("map.png")
        header = struct.pack(">II", width, 20) + ihdr[8:]
        fidelity._write_png_shifted(path, (width, 20, bpp, header, rows[:20]), 0, 0)
        args = fidelity.parse_args([path, "--bin", clitest.BIN_DIR, "--cache", self.path("cache")])
        harness = fidelity.Harness(args)
        minfo = harness.map_info(path)
        self.assertEqual((minfo["width"], minfo["height"]), (32, 20))
        params = {"res": 32, "sigma_r": 0.02}
        # (x, y, sigma) and the periods each axis is repeated over: 2 x 2, 2 x 6, 6 x 1.
        for x, y, sigma in ((7, 3, 5.0), (29, 18, 9.0), (12, 5, 14.0)):
            with self.subTest(x=x, y=y, sigma=sigma):
                splat = self.path("splat.exr")
                harness.splat_reference(path, minfo, x, y, sigma, params, [], splat)
                exact = self.path("exact.exr")
                self.run_ok("glintref", "-q", "image", path, "--at", "%d,%d" % (x, y), "--sigma", sigma,
                            "--res", params["res"], "--sigma-r", params["sigma_r"], "-o", exact)
                error = fidelity._rel_l1(fidelity._read_exr(splat)[2], fidelity._read_exr(exact)[2])
                self.assertLess(error, 2e-3)


if __name__ == "__main__":
    clitest.main()
