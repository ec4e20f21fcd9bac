# SPDX-License-Identifier: Apache-2.0
"""glintref render and compare: the --json summaries against their schemas, the asset against the
reference at the pyramid's centres, a white furnace in every mode, determinism for a seed and any
-j, every object and light type, and the documented errors."""

import json
import os

import clitest
from clitest import BAD_ARGS, DIFFERENCES, INVALID, IO


def write_scene(path, scene):
    with open(path, "w") as f:
        json.dump(scene, f)
    return path


class RenderTest(clitest.ToolTestCase):
    def render(self, scene_path, out, *args):
        return self.run_json("glintref", "render", scene_path, "-o", out, *args,
                             schema="glintref-render.schema.json")

    def compare(self, a, b, *args):
        return self.run_json("glintref", "compare", a, b, *args, schema="glintref-compare.schema.json")

    # An orthographic top view whose pixel centres are the footprint centres of a pyramid with
    # stride 4 on a 64^2 map (16 x 16 pixels), and whose pixel footprint std (0.5 px = 2 texels)
    # is the level-0 sigma.
    def centres_scene(self, normal_map, asset, lights):
        return write_scene(self.path("centres.json"), {
            "camera": {"type": "orthographic", "position": [0, 3, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
                       "ortho_height": 2.0, "width": 16, "height": 16, "pixel_sigma": 0.5},
            "object": {"type": "plane", "size": 2.0},
            "material": {"normal_map": normal_map, "asset": asset, "alpha": 0.05, "sigma_r": 0.02,
                         "fresnel": {"type": "none"}},
            "lights": lights,
        })

    def test_asset_matches_reference_at_pyramid_centres(self):
        # Stated bound: relative MSE below 3% with 128 NDF bins per side; the difference is the
        # pyramid's bin averaging, so it shrinks as the bins get finer.
        nmap = self.mapgen("beckmann", "b.exr", "--size", "64", "--seed", "5", "--alpha", "0.4")
        lights = [{"type": "point", "position": [0.5, 2.0, 0.3], "intensity": [4, 4, 4]},
                  {"type": "directional", "direction": [-0.3, 1.0, 0.1], "irradiance": [1, 1, 1]}]
        scene = self.centres_scene(nmap, self.path("p.gbk"), lights)
        ref = self.render(scene, self.path("ref.exr"), "--ndf", "reference")
        self.assertAlmostEqual(ref["footprint_sigma_texels"]["mean"], 2.0, places=9)
        self.assertEqual(ref["pixels_hit"], 256)
        errors = {}
        for res in (64, 128, 256):
            # The pyramid alone (--no-flakes): its centres, seen through R x R bins.
            self.run_ok("ndfgen", nmap, "-o", self.path("p.gbk"), "--stride", "4", "--sigma0", "2", "--levels", "2",
                        "--ndf-res", str(res), "--sigma-r", "0.02", "--no-flakes", "--quiet")
            self.render(scene, self.path(f"asset{res}.exr"), "--ndf", "asset")
            errors[res] = self.compare(self.path(f"asset{res}.exr"), self.path("ref.exr"))["relative_mse"]
        print("relative MSE asset vs reference at the centres:", errors)
        self.assertLess(errors[128], 0.03)
        self.assertLess(errors[256], errors[64])
        self.assertLess(errors[256], 0.01)
        # With its flakes (the default) the asset answers these footprints exactly, whatever R.
        self.run_ok("ndfgen", nmap, "-o", self.path("p.gbk"), "--stride", "4", "--sigma0", "2", "--levels", "2",
                    "--ndf-res", "64", "--sigma-r", "0.02", "--quiet")
        self.render(scene, self.path("flakes.exr"), "--ndf", "asset")
        self.assertLess(self.compare(self.path("flakes.exr"), self.path("ref.exr"))["relative_mse"], 1e-6)

    def test_white_furnace(self):
        # A flat map under a uniform white environment, F = 1 and a near-mirror shadowing roughness:
        # every pixel reflects the environment's radiance (albedo 1) in every mode.
        nmap = self.mapgen("flat", "flat.exr", "--size", "32")
        self.run_ok("ndfgen", nmap, "-o", self.path("flat.gbk"), "--stride", "8", "--sigma0", "4", "--levels", "2",
                    "--ndf-res", "64", "--quiet")
        scene = write_scene(self.path("furnace.json"), {
            "camera": {"position": [0, 2.0, 1.2], "look_at": [0, 0, 0], "fov_degrees": 30, "width": 24, "height": 24},
            "object": {"type": "plane", "size": 40.0, "uv_scale": 4.0},
            "material": {"normal_map": nmap, "asset": self.path("flat.gbk"), "alpha": 0.001,
                         "fresnel": {"type": "none"}},
            "lights": [{"type": "uniform", "radiance": [1, 1, 1]}],
        })
        for mode in ("smooth", "asset", "reference"):
            doc = self.render(scene, self.path(f"f_{mode}.exr"), "--ndf", mode, "--spp", "4")
            self.assertEqual(doc["pixels_hit"], 24 * 24)
            for c in doc["mean_radiance"]:
                self.assertAlmostEqual(c, 1.0, delta=0.02, msg=f"--ndf {mode}")

    def test_deterministic_for_seed_and_threads(self):
        nmap = self.mapgen("flakes", "fl.exr", "--size", "64", "--seed", "2")
        scene = write_scene(self.path("s.json"), {
            "camera": {"position": [0, 2.0, 1.0], "look_at": [0, 0, 0], "width": 20, "height": 20},
            "object": {"type": "plane", "size": 2.0},
            "material": {"normal_map": nmap, "alpha": 0.2, "sigma_r": 0.02},
            "lights": [{"type": "sg", "axis": [0.3, 0.8, 0.5], "sharpness": 50, "amplitude": [2, 2, 2]},
                       {"type": "rectangle", "corner": [-1, 2, -1], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1],
                        "radiance": [3, 3, 3]}],
        })
        hashes = []
        for j in ("1", "2", "2"):
            out = self.path(f"d{len(hashes)}.exr")
            self.run_ok("glintref", "render", scene, "-o", out, "--ndf", "reference", "--spp", "3", "--seed", "7",
                        "-j", j, "--quiet")
            hashes.append(clitest.file_hash(out))
        self.assertEqual(len(set(hashes)), 1)
        # Another seed draws other samples.
        self.run_ok("glintref", "render", scene, "-o", self.path("other.exr"), "--ndf", "reference", "--spp", "3",
                    "--seed", "8", "--quiet")
        self.assertNotEqual(clitest.file_hash(self.path("other.exr")), hashes[0])

    def test_objects_lights_and_prefiltering(self):
        nmap = self.mapgen("beckmann", "bk.exr", "--size", "64", "--seed", "3", "--alpha", "0.3")
        self.run_ok("ndfgen", nmap, "-o", self.path("bk.gbk"), "--stride", "8", "--sigma0", "4", "--ndf-res", "64",
                    "--sigma-r", "0.02", "--quiet")
        for obj in ({"type": "plane", "size": 3.0}, {"type": "sphere", "radius": 1.0, "uv_scale": 2.0},
                    {"type": "bent_quad", "size": 2.0, "bend_degrees": 120.0}):
            scene = write_scene(self.path("o.json"), {
                "camera": {"position": [0, 1.5, 2.5], "look_at": [0, 0, 0], "width": 32, "height": 32},
                "object": obj,
                "material": {"normal_map": nmap, "asset": self.path("bk.gbk"), "alpha": 0.2, "sigma_r": 0.02},
                "lights": [{"type": "sg", "axis": [0.0, 0.9, -0.4], "sharpness": 400, "amplitude": [30, 30, 30]}],
            })
            pre = self.render(scene, self.path("pre.exr"), "--ndf", "asset", "--preview", self.path("pre.png"))
            self.assertGreater(pre["pixels_hit"], 100, obj["type"])
            self.assertTrue(os.path.exists(self.path("pre.png")))
            smp = self.render(scene, self.path("smp.exr"), "--ndf", "asset", "--env", "sample", "--spp", "64")
            # The prefiltered SG shading and MIS sampling of the same asset agree on the mean.
            self.assertGreater(smp["mean_radiance"][0], 0.0)
            self.assertAlmostEqual(pre["mean_radiance"][0] / smp["mean_radiance"][0], 1.0, delta=0.25,
                                   msg=obj["type"])

    def test_ltc_area_light_matches_sampling(self):
        # A rectangle light on the smooth GGX BRDF: the LTC table (a small, quick fit) and MIS sampling
        # agree within the fit's accuracy and the sampling noise.
        table = self.path("ggx.gbk")
        self.run_ok("ltcfit", "table", "--brdf", "ggx", "--size", "16", "--samples", "16", "-o", table, "--quiet")
        scene = write_scene(self.path("area.json"), {
            "camera": {"position": [0, 2.0, 2.5], "look_at": [0, 0, 0], "width": 32, "height": 32},
            "object": {"type": "plane", "size": 4.0},
            "material": {"alpha": 0.3, "fresnel": {"type": "schlick", "f0": [0.9, 0.6, 0.3]}},
            "lights": [{"type": "rectangle", "corner": [-0.5, 1.0, -1.5], "edge_u": [1.0, 0.0, 0.0],
                        "edge_v": [0.0, 0.6, -0.3], "radiance": [5, 5, 5]}],
        })
        ltc = self.render(scene, self.path("ltc.exr"), "--ltc", table)
        self.assertEqual(ltc["area"], "ltc")
        smp = self.render(scene, self.path("smp.exr"), "--spp", "256")
        self.assertEqual(smp["area"], "sample")
        for a, b in zip(ltc["mean_radiance"], smp["mean_radiance"]):
            self.assertAlmostEqual(a / b, 1.0, delta=0.03)
        err = self.compare(self.path("ltc.exr"), self.path("smp.exr"))["relative_mse"]
        print("relative MSE LTC vs sampling:", err)
        self.assertLess(err, 0.02)
        self.assert_fails(BAD_ARGS, "glintref", "render", scene, "-o", self.path("x.exr"), "--ltc", table, "--ndf",
                          "reference", outputs=[self.path("x.exr")])

    # A 16 x 12 view of a plane with a 32^2 Beckmann-like map under a point light.
    def small_scene(self):
        nmap = self.mapgen("beckmann", "c.exr", "--size", "32")
        return write_scene(self.path("c.json"), {
            "camera": {"position": [0, 2, 2], "width": 16, "height": 12},
            "object": {"type": "plane"},
            "material": {"normal_map": nmap, "alpha": 0.3},
            "lights": [{"type": "point", "position": [0, 2, -1], "intensity": [5, 5, 5]}],
        })

    def test_compare(self):
        scene = self.small_scene()
        a, b = self.path("a.exr"), self.path("b.exr")
        self.run_ok("glintref", "render", scene, "-o", a, "--ndf", "smooth", "--quiet")
        self.run_ok("glintref", "render", scene, "-o", b, "--ndf", "reference", "--quiet")
        same = self.compare(a, a)
        self.assertEqual(same["rmse"], 0.0)
        self.assertIsNone(same["psnr"])
        diff = self.compare(a, b, "--heatmap", self.path("heat.png"))
        self.assertGreater(diff["rmse"], 0.0)
        self.assertGreater(diff["relative_mse"], 0.0)
        self.assertTrue(os.path.exists(self.path("heat.png")))
        code, out, _ = clitest.run("glintref", "compare", a, b, "--max-rel-mse", "1e-9", "--json")
        self.assertEqual(code, DIFFERENCES)
        self.assertFalse(json.loads(out)["within_threshold"])
        self.run_ok("glintref", "render", scene, "-o", self.path("small.exr"), "--image-size", "8,8", "--quiet")
        self.assert_fails(INVALID, "glintref", "compare", a, self.path("small.exr"))
        self.assert_fails(IO, "glintref", "compare", a, self.path("missing.exr"))

    def test_render_compare_matches_compare(self):
        # render --compare gives glintref compare's figures for the file it wrote, in one run.
        scene = self.small_scene()
        ref, img, heat = self.path("ref.exr"), self.path("img.exr"), self.path("heat.png")
        self.run_ok("glintref", "render", scene, "-o", ref, "--ndf", "reference", "--quiet")
        doc = self.render(scene, img, "--ndf", "smooth", "--compare", ref, "--heatmap", heat)
        alone = self.compare(img, ref, "--heatmap", self.path("heat2.png"))
        for key in ("rmse", "relative_mse", "psnr", "peak", "max_abs_error", "differing_values"):
            self.assertEqual(doc["compare"][key], alone[key], key)
        self.assertGreater(doc["compare"]["relative_mse"], 0.0)
        self.assertEqual(doc["compare"]["reference"], "ref.exr")
        with open(heat, "rb") as f, open(self.path("heat2.png"), "rb") as g:
            self.assertEqual(f.read(), g.read())
        # A missing or mis-sized reference fails before anything is written; --heatmap needs --compare.
        out = self.path("out.exr")
        self.assert_fails(IO, "glintref", "render", scene, "-o", out, "--compare", self.path("none.exr"),
                          outputs=[out])
        self.run_ok("glintref", "render", scene, "-o", self.path("small.exr"), "--image-size", "8,8", "--quiet")
        self.assert_fails(INVALID, "glintref", "render", scene, "-o", out, "--compare", self.path("small.exr"),
                          "--heatmap", self.path("h.png"), outputs=[out, self.path("h.png")])
        self.assert_fails(BAD_ARGS, "glintref", "render", scene, "-o", out, "--heatmap", self.path("h.png"),
                          outputs=[out])
        self.assert_fails(BAD_ARGS, "glintref", "render", scene, "-o", out, "--compare", ref, "--heatmap",
                          self.path("h.jpg"), outputs=[out])
        # The reference is not the render's own output (it would be overwritten before the comparison).
        before = clitest.file_hash(ref)
        self.assert_fails(BAD_ARGS, "glintref", "render", scene, "-o", ref, "--compare", ref)
        self.assertEqual(clitest.file_hash(ref), before)

    def test_errors(self):
        nmap = self.mapgen("flat", "e.exr", "--size", "16")
        good = {"camera": {"width": 8, "height": 8}, "object": {"type": "plane"}, "material": {"normal_map": nmap}}
        scene = write_scene(self.path("good.json"), good)
        out = self.path("out.exr")
        self.assert_fails(IO, "glintref", "render", self.path("none.json"), "-o", out, outputs=[out])
        with open(self.path("bad.json"), "w") as f:
            f.write("{ not json")
        self.assert_fails(INVALID, "glintref", "render", self.path("bad.json"), "-o", out, outputs=[out])
        bad = dict(good, camera={"width": 0})
        self.assert_fails(INVALID, "glintref", "render", write_scene(self.path("b1.json"), bad), "-o", out,
                          outputs=[out])
        bad = dict(good, object={"type": "torus"})
        self.assert_fails(INVALID, "glintref", "render", write_scene(self.path("b2.json"), bad), "-o", out,
                          outputs=[out])
        bad = dict(good, lights=[{"type": "point"}])
        self.assert_fails(INVALID, "glintref", "render", write_scene(self.path("b3.json"), bad), "-o", out,
                          outputs=[out])
        self.assert_fails(BAD_ARGS, "glintref", "render", scene, "-o", out, "--spp", "0", outputs=[out])
        self.assert_fails(BAD_ARGS, "glintref", "render", scene, "-o", self.path("out.png"), outputs=[out])
        self.assert_fails(BAD_ARGS, "glintref", "render", scene, "-o", out, "--ndf", "asset", outputs=[out])
        self.assert_fails(BAD_ARGS, "glintref", "render", scene, "-o", out, "--ndf", "fancy", outputs=[out])
        self.assert_fails(IO, "glintref", "render", scene, "-o", self.path("nodir/out.exr"))
        with open(self.path("corrupt.gbk"), "wb") as f:
            f.write(b"GLNT" + b"\0" * 60)
        self.assert_fails(INVALID, "glintref", "render", scene, "-o", out, "--ndf", "asset", "--asset",
                          self.path("corrupt.gbk"), outputs=[out])
        # The scene's example files validate against the scene schema.
        examples = os.path.join(clitest.SOURCE_DIR, "examples", "scenes")
        for name in sorted(os.listdir(examples)):
            if name.endswith(".json"):
                with open(os.path.join(examples, name)) as f:
                    clitest.validate(json.load(f), "scene.schema.json")


if __name__ == "__main__":
    clitest.main()
