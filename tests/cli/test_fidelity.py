# SPDX-License-Identifier: Apache-2.0
"""scripts/fidelity.py: its splatted references of large footprints (one footprint baked by ndfgen
on a shifted copy of the map) are the images the exact reference evaluator gives, on axes that the
footprint is flat over, and on axes repeated over 2 and 6 periods; its target check finds the worst
cells and every miss, and leaves the ratio out where the baseline is at float rounding."""

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


class Targets(clitest.ToolTestCase):
    @staticmethod
    def results(cells):
        """One map; cells: (sigma, asset errors, baseline errors)."""
        rows = [{"sigma": sigma, "footprints": [{}] * len(errors), "errors": {"a": errors, "baseline": base}}
                for sigma, errors, base in cells]
        return {"baseline": "splat", "maps": [{"map": {"name": "m.png", "width": 64, "height": 64}, "bakes": {},
                                               "sigmas": rows}]}

    def test_worst_cells_and_misses(self):
        results = self.results([
            (1.0, [0.01, 0.02, 0.03], [1.0, 1.2, 1.4]),      # meets all three
            (8.0, [0.10, 0.11, 0.40], [0.5, 0.5, 0.5]),      # 90th percentile 0.342 > 0.25
            (32.0, [0.05, 0.06, 0.07], [0.1, 0.1, 0.1]),     # ratio 0.6 > 0.35
            (256.0, [2e-5, 3e-5, 4e-5], [3e-6, 3e-6, 4e-6]),  # both at float rounding: met
        ])
        t = fidelity.check_targets(results, ["a"], (0.12, 0.25, 0.35), 1e-4)["assets"]["a"]
        self.assertEqual([(m["sigma"], m["missed"]) for m in t["misses"]], [(8.0, ["p90"]), (32.0, ["ratio"])])
        self.assertEqual(t["worst"]["median"]["sigma"], 8.0)
        self.assertAlmostEqual(t["worst"]["median"]["value"], 0.11)
        self.assertAlmostEqual(t["worst"]["p90"]["value"], 0.342)
        self.assertEqual(t["worst"]["ratio"]["sigma"], 32.0)
        self.assertAlmostEqual(t["worst"]["ratio"]["value"], 0.6)
        # Below the floor the baseline is not a ratio's denominator, but the asset must be there too.
        results = self.results([(256.0, [5e-4, 6e-4, 7e-4], [3e-6, 3e-6, 4e-6])])
        t = fidelity.check_targets(results, ["a"], (0.12, 0.25, 0.35), 1e-4)["assets"]["a"]
        self.assertEqual([m["missed"] for m in t["misses"]], [["floor"]])
        self.assertIsNone(t["worst"]["ratio"])
        md = fidelity.render_markdown(dict(results, targets=fidelity.check_targets(
            results, ["a"], (0.12, 0.25, 0.35), 1e-4)), ["a"])
        self.assertIn("m.png 256: floor", md)
        # An asset with no measurement (its bake failed) misses on that map.
        t = fidelity.check_targets(results, ["a", "b"], (0.12, 0.25, 0.35), 1e-4)["assets"]["b"]
        self.assertEqual([(m["map"], m["missed"]) for m in t["misses"]], [("m.png", ["not measured"])])

    def test_each_asset_is_measured_against_its_own_baseline(self):
        # Assets of two NDF resolutions: two references and two baselines, one per resolution.
        row = {"sigma": 32.0, "footprints": [{}] * 3,
               "errors": {"a": [0.05, 0.06, 0.07], "b": [0.05, 0.06, 0.07],
                          "baseline R32": [0.1, 0.1, 0.1], "baseline R64": [0.5, 0.5, 0.5]},
               "baseline_of": {"a": "baseline R32", "b": "baseline R64"}}
        results = {"baseline": "splat", "maps": [{"map": {"name": "m.png"}, "bakes": {}, "sigmas": [row]}]}
        t = fidelity.check_targets(results, ["a", "b"], (0.12, 0.25, 0.35), 1e-4)["assets"]
        self.assertAlmostEqual(t["a"]["worst"]["ratio"]["value"], 0.6)
        self.assertEqual([m["missed"] for m in t["a"]["misses"]], [["ratio"]])
        self.assertAlmostEqual(t["b"]["worst"]["ratio"]["value"], 0.12)
        self.assertEqual(t["b"]["misses"], [])


if __name__ == "__main__":
    clitest.main()
