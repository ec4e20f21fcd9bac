# SPDX-License-Identifier: Apache-2.0
"""glintref render on tensor-ndf assets (tensorpack): the renders approach the reference as the CP
rank rises (rank 32 closer than 16, 16 closer than 8), both against the reference P-NDF and against
the uncompressed pyramid the tensors compress."""

import json

import clitest


class RenderTensorTest(clitest.ToolTestCase):
    def test_rank_ordering(self):
        nmap = self.mapgen("flakes", "f.exr", "--size", "128", "--seed", "12", "--cone", "12", "--cell", "8")
        pyramid = self.path("f_pyramid.gbk")
        # sigma_r = 0.02 (lobes about 1.3 bins wide at R = 128): the pyramid's own error against the
        # reference (bin averaging of much sharper lobes) then stays below the compression error, so
        # the rank ordering is visible against the reference too.
        # No flakes: the compressed levels themselves answer these footprints (with flakes, the clustered
        # lobes would answer them whatever the rank).
        self.run_ok("ndfgen", nmap, "-o", pyramid, "--sigma-r", "0.02", "--no-flakes", "--quiet")
        # A tilted plane whose pixel footprints (std about 8 texels) sit at the pyramid's level 0.
        scene = self.path("rank.json")
        with open(scene, "w") as f:
            json.dump({
                "camera": {"position": [0, 1.6, 0.9], "look_at": [0, 0, 0], "fov_degrees": 40, "width": 48,
                           "height": 48},
                "object": {"type": "plane", "size": 20.0, "uv_scale": 80.0},
                "material": {"normal_map": nmap, "sigma_r": 0.02, "alpha": 0.1, "fresnel": {"type": "none"}},
                "lights": [{"type": "point", "position": [0.3, 1.5, -0.8], "intensity": [3, 3, 3]},
                           {"type": "directional", "direction": [-0.2, 0.87, -0.45], "irradiance": [0.6, 0.6, 0.6]}],
            }, f)
        ref = self.path("ref.exr")
        doc = self.run_json("glintref", "render", scene, "-o", ref, "--ndf", "reference",
                            schema="glintref-render.schema.json")
        self.assertGreater(doc["footprint_sigma_texels"]["mean"], 6.0)
        self.run_ok("glintref", "render", scene, "-o", self.path("pyr.exr"), "--ndf", "asset", "--asset", pyramid,
                    "--quiet")
        vs_ref, vs_pyr = {}, {}
        for rank in (8, 16, 32):
            asset = self.path(f"r{rank}.gbk")
            self.run_ok("tensorpack", "--rank", str(rank), "--exact-levels", "0", pyramid, "-o", asset, "--quiet")
            img = self.path(f"r{rank}.exr")
            doc = self.run_json("glintref", "render", scene, "-o", img, "--ndf", "asset", "--asset", asset,
                                schema="glintref-render.schema.json")
            self.assertEqual(doc["ndf"], "asset")
            vs_ref[rank] = self.run_json("glintref", "compare", img, ref,
                                         schema="glintref-compare.schema.json")["relative_mse"]
            vs_pyr[rank] = self.run_json("glintref", "compare", img, self.path("pyr.exr"),
                                         schema="glintref-compare.schema.json")["relative_mse"]
        print("relative MSE against the reference:", vs_ref)
        print("relative MSE against the uncompressed pyramid:", vs_pyr)
        self.assertLess(vs_ref[32], vs_ref[16])
        self.assertLess(vs_ref[16], vs_ref[8])
        self.assertLess(vs_pyr[32], vs_pyr[16])
        self.assertLess(vs_pyr[16], vs_pyr[8])


if __name__ == "__main__":
    clitest.main()
