# SPDX-License-Identifier: Apache-2.0
"""tensorpack: tensor-ndf assets from normal maps and ndf-pyramid containers. Schema-valid --json,
the default output name, byte-identical output for every thread count and run, and the documented
exit codes for bad arguments and bad input with nothing left behind."""

import json
import math
import os
import shutil
import struct

import clitest
from clitest import ToolTestCase, run

PYRAMID = ["--ndf-res", "32", "--stride", "8", "--sigma0", "4"]
PACK = ["--rank", "8", "--block", "16", "--quiet"]
# These tests are about the compression: on their small maps every level would fit the default
# budget of levels stored exactly (test_exact_levels covers that).
NOEXACT = ["--exact-levels", "0"]


def write_half_exr(path, width, height, texel):
    """A scanline, uncompressed, half-float RGB EXR; texel(x, y) gives (r, g, b)."""
    def attribute(name, kind, data):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(data)) + data

    channels = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1) for c in "BGR") + b"\0"
    window = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<I", 2) + attribute("channels", "chlist", channels) +
              attribute("compression", "compression", b"\0") + attribute("dataWindow", "box2i", window) +
              attribute("displayWindow", "box2i", window) + attribute("lineOrder", "lineOrder", b"\0") +
              attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)) +
              attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)) +
              attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    line = 8 + width * 3 * 2
    first = len(header) + 8 * height
    table = b"".join(struct.pack("<Q", first + y * line) for y in range(height))
    lines = []
    for y in range(height):
        row = [texel(x, y) for x in range(width)]
        data = b"".join(struct.pack("<%de" % width, *[t[c] for t in row]) for c in (2, 1, 0))  # B, G, R
        lines.append(struct.pack("<ii", y, len(data)) + data)
    with open(path, "wb") as f:
        f.write(header + table + b"".join(lines))


def one_axis_normal(t, size):
    """A brushed-like normal that depends on one coordinate t only: n_x within +-0.02, n_y within
    +-0.5 (smooth periodic profiles)."""
    w = 2.0 * math.pi / size
    nx = 0.02 * (math.sin(3 * w * t + 0.4) + 0.5 * math.sin(7 * w * t + 0.8)) / 1.5
    ny = 0.5 * (math.sin(2 * w * t + 1.3) + 0.5 * math.sin(5 * w * t + 2.6)) / 1.5
    return nx, ny, math.sqrt(1.0 - nx * nx - ny * ny)


class TensorPack(ToolTestCase):
    def test_help_and_version(self):
        code, out, _ = run("tensorpack", "--help")
        self.assertEqual(code, clitest.OK)
        for option in ("--rank", "--block", "--error-target", "--max-error", "--blank-threshold", "--precision", "--nonneg",
                       "--ndf-res", "--json", "--depfile", "--threads"):
            self.assertIn(option, out)
        code, out, _ = run("tensorpack", "--version")
        self.assertEqual(code, clitest.OK)
        self.assertIn("tensorpack", out)

    def test_json_report_and_default_output_name(self):
        m = self.mapgen("scratches", "scr.png", "--size", "32", "--seed", "5")
        doc = self.run_json("tensorpack", *NOEXACT, m, *PYRAMID, *PACK, schema="tensorpack.schema.json")
        out = self.path("scr.gbk")  # beside the input, extension replaced
        self.assertTrue(os.path.exists(out))
        self.assertEqual(doc["output"], "scr.gbk")
        self.assertEqual(doc["source"], "normal-map")
        self.assertEqual(doc["file_bytes"], os.path.getsize(out))
        self.assertEqual(doc["groups"], sum(l["groups"] for l in doc["levels"]))
        self.assertEqual(doc["blocks_kept"], sum(l["blocks_kept"] for l in doc["levels"]))
        self.assertEqual(doc["raw_bytes"], sum(l["raw_bytes"] for l in doc["levels"]))
        self.assertEqual(sum(doc["rank_histogram"].values()), doc["groups"])
        self.assertEqual(doc["rank_histogram"], {"8": doc["groups"]})
        self.assertLess(doc["ratio"], 1.0)
        self.assertGreater(doc["relative_error"], 0.0)
        self.assertLess(doc["relative_error"], 1.0)
        self.assertEqual(doc["negative_mass_fraction"], 0.0)  # non-negative factors by default
        signed = self.run_json("tensorpack", *NOEXACT, m, "-o", self.path("signed.gbk"), *PYRAMID, *PACK, "--no-nonneg",
                               schema="tensorpack.schema.json")
        self.assertFalse(signed["parameters"]["nonneg"])
        self.assertGreater(signed["negative_mass_fraction"], 0.0)
        if os.path.exists(clitest.tool_path("glintinfo")):
            code, _, err = run("glintinfo", "validate", out)
            self.assertEqual(code, clitest.OK, err)
            code, info, err = run("glintinfo", "info", out, "--json")
            self.assertEqual(code, clitest.OK, err)
            self.assertIn("tensor-ndf", info)

    def test_pyramid_container_input(self):
        m = self.mapgen("flakes", "fl.png", "--size", "32")
        pyramid = self.path("fl.gbk")
        self.run_ok("ndfgen", m, "-o", pyramid, *PYRAMID, "--quiet")
        doc = self.run_json("tensorpack", *NOEXACT, pyramid, *PACK, "--error-target", "0.2",
                            schema="tensorpack.schema.json")
        self.assertEqual(doc["source"], "ndf-pyramid")
        self.assertIsNone(doc["map"])
        self.assertEqual(doc["output"], "fl.tensor.gbk")  # never overwrites its input
        self.assertTrue(os.path.exists(self.path("fl.tensor.gbk")))
        self.assertLessEqual(doc["max_rank"], 8)
        # Pyramid options belong to map inputs.
        out = self.path("x.gbk")
        self.assert_fails(clitest.BAD_ARGS, "tensorpack", *NOEXACT, pyramid, "-o", out, *PACK, "--ndf-res", "64",
                          outputs=[out])

    def test_identical_bytes_for_any_thread_count_and_run(self):
        m = self.mapgen("beckmann", "b.png", "--size", "48")
        a, b, c = self.path("a.gbk"), self.path("b.gbk"), self.path("c.gbk")
        self.run_ok("tensorpack", *NOEXACT, m, "-o", a, *PYRAMID, *PACK, "-j", "1")
        self.run_ok("tensorpack", *NOEXACT, m, "-o", b, *PYRAMID, *PACK, "-j", "2")
        self.run_ok("tensorpack", *NOEXACT, m, "-o", c, *PYRAMID, *PACK, "-j", "2")
        self.assertEqual(clitest.file_hash(a), clitest.file_hash(b))
        self.assertEqual(clitest.file_hash(b), clitest.file_hash(c))

    def test_depfile(self):
        m = self.mapgen("brushed", "br.png", "--size", "32")
        out, dep = self.path("br.gbk"), self.path("br.d")
        self.run_ok("tensorpack", *NOEXACT, m, "-o", out, *PYRAMID, *PACK, "--depfile", dep)
        with open(dep) as f:
            text = f.read()
        self.assertIn("br.gbk", text)
        self.assertIn("br.png", text)

    def test_one_axis_signed_half_exr_maps(self):
        # Normals that vary along x only, or along y only: every NDF image is a thin line at s_x ~ 0
        # on a block boundary, so the CP groups are rank deficient. The default non-negative bake
        # (the default pyramid, --rank 16) used to fail with exit 4 and non-finite factors.
        size = 64
        for axis in ("x", "y"):
            m = self.path(f"one_axis_{axis}.exr")
            write_half_exr(m, size, size, lambda x, y: one_axis_normal(x if axis == "x" else y, size))
            doc = self.run_json("tensorpack", *NOEXACT, m, "--rank", "16", "--quiet", schema="tensorpack.schema.json")
            self.assertEqual(doc["map"], {"width": size, "height": size, "wrap": "repeat"})
            self.assertTrue(doc["parameters"]["nonneg"])
            self.assertEqual(doc["negative_mass_fraction"], 0.0)
            self.assertGreater(doc["relative_error"], 0.0)
            self.assertLess(doc["relative_error"], 0.5, axis)
            self.assertLess(doc["max_group_error"], 0.5, axis)
            if os.path.exists(clitest.tool_path("glintinfo")):
                code, _, err = run("glintinfo", "validate", self.path(f"one_axis_{axis}.gbk"))
                self.assertEqual(code, clitest.OK, err)

    def warnings_on_stderr(self, err):
        lines = [l for l in err.splitlines() if "warning" in l]
        for l in lines:
            self.assertTrue(l.startswith("tensorpack: warning: "), l)
        return lines

    def test_quality_warnings(self):
        m = self.mapgen("flakes", "fl.png", "--size", "32", "--seed", "3")
        # A fit within the default bound: no warning.
        out, err = self.run_ok("tensorpack", *NOEXACT, m, "-o", self.path("good.gbk"), *PYRAMID, "--rank", "8", "--block", "16",
                               "--json")
        doc = json.loads(out)
        clitest.validate(doc, "tensorpack.schema.json")
        self.assertLessEqual(doc["gated_error"]["error"], 0.5)
        self.assertEqual(doc["warnings"], [])
        self.assertEqual(self.warnings_on_stderr(err), [])
        # Rank 1 leaves most of the structure: above the default bound 0.5, one warning line, the
        # same message in --json, and the asset is still written.
        bad = self.path("bad.gbk")
        out, err = self.run_ok("tensorpack", *NOEXACT, m, "-o", bad, *PYRAMID, "--rank", "1", "--block", "16", "--json")
        doc = json.loads(out)
        clitest.validate(doc, "tensorpack.schema.json")
        self.assertGreater(doc["gated_error"]["error"], 0.5)
        self.assertEqual(len(doc["warnings"]), 1)
        self.assertIn("default bound 0.5", doc["warnings"][0])
        lines = self.warnings_on_stderr(err)
        self.assertEqual(len(lines), 1)
        self.assertIn(doc["warnings"][0], lines[0])
        self.assertTrue(os.path.exists(bad))
        # --quiet keeps the warning on stderr; -qq drops it (the reporter's convention); --json keeps it.
        out, err = self.run_ok("tensorpack", *NOEXACT, m, "-o", bad, *PYRAMID, "--rank", "1", "--block", "16", "--json",
                               "--quiet")
        self.assertEqual(len(self.warnings_on_stderr(err)), 1)
        out, err = self.run_ok("tensorpack", *NOEXACT, m, "-o", bad, *PYRAMID, "--rank", "1", "--block", "16", "--json",
                               "-qq")
        self.assertEqual(self.warnings_on_stderr(err), [])
        self.assertEqual(len(json.loads(out)["warnings"]), 1)
        # A missed --error-target warns whatever the default bound says.
        out, err = self.run_ok("tensorpack", *NOEXACT, m, "-o", self.path("target.gbk"), *PYRAMID, "--rank", "2", "--block",
                               "16", "--error-target", "0.001", "--json")
        doc = json.loads(out)
        clitest.validate(doc, "tensorpack.schema.json")
        self.assertEqual(len(doc["warnings"]), 1)
        self.assertIn("misses --error-target 0.0010", doc["warnings"][0])
        self.assertEqual(len(self.warnings_on_stderr(err)), 1)

    def test_max_error_gate(self):
        m = self.mapgen("scratches", "s.png", "--size", "32", "--seed", "5")
        ref = self.path("ref.gbk")
        doc = self.run_json("tensorpack", *NOEXACT, m, "-o", ref, *PYRAMID, *PACK, schema="tensorpack.schema.json")
        achieved = doc["gated_error"]["error"]
        # Exceeded: runtime failure, one line naming the achieved error, nothing written.
        out = self.path("gated.gbk")
        err = self.assert_fails(clitest.RUNTIME, "tensorpack", *NOEXACT, m, "-o", out, *PYRAMID, *PACK, "--max-error",
                                "%.6f" % (achieved * 0.5), outputs=[out])
        self.assertIn("--max-error", err)
        err = self.assert_fails(clitest.RUNTIME, "tensorpack", *NOEXACT, m, "-o", out, *PYRAMID, *PACK, "--json",
                                "--max-error", "0", outputs=[out])
        # Met: the gate does not change a byte.
        self.run_ok("tensorpack", *NOEXACT, m, "-o", out, *PYRAMID, *PACK, "--max-error", "%.6f" % (achieved * 1.01 + 1e-6))
        self.assertEqual(clitest.file_hash(out), clitest.file_hash(ref))
        for bad in ("-1", "nan", "inf"):
            self.assert_fails(clitest.BAD_ARGS, "tensorpack", *NOEXACT, m, "-o", self.path("x.gbk"), *PYRAMID, *PACK,
                              "--max-error", bad, outputs=[self.path("x.gbk")])

    def test_gate_skips_the_levels_the_lobes_answer(self):
        m = self.mapgen("flakes", "fl.png", "--size", "32", "--seed", "3")
        # With lobes the gate covers only the levels the pyramid answers with: from the first
        # level from which every level is within the faithful bound, or the top level alone.
        doc = self.run_json("tensorpack", *NOEXACT, m, "-o", self.path("b.gbk"), *PYRAMID, "--rank", "1", "--block", "16",
                            schema="tensorpack.schema.json")
        gated = doc["gated_error"]
        self.assertIsNotNone(gated["from_sigma"])
        sigmas = [lv["sigma"] for lv in doc["levels"]]
        levels = [lv["relative_error"] for lv in doc["levels"]]
        first = sigmas.index(gated["from_sigma"])
        self.assertAlmostEqual(gated["error"], max(levels[first:]), places=12)
        self.assertLessEqual(gated["error"], max(doc["relative_error"], doc["max_group_error"]))
        # Without lobes every level answers and is gated.
        doc = self.run_json("tensorpack", *NOEXACT, m, "-o", self.path("c.gbk"), *PYRAMID, "--rank", "1", "--block", "16",
                            "--lobes", "0", schema="tensorpack.schema.json")
        self.assertIsNone(doc["gated_error"]["from_sigma"])
        self.assertEqual(doc["gated_error"]["error"], max(doc["relative_error"], doc["max_group_error"]))

    def test_from_container_keeps_the_lobes_of_its_source(self):
        m = self.mapgen("flakes", "fl.png", "--size", "32", "--seed", "3")
        for lobes in ("0", "4"):
            src = self.path("p%s.gbk" % lobes)
            self.run_ok("ndfgen", m, "-o", src, *PYRAMID, "--lobes", lobes, "--quiet")
            out = self.path("t%s.gbk" % lobes)
            self.run_ok("tensorpack", *NOEXACT, src, "-o", out, *PACK)
            info = self.run_json("glintinfo", "info", out, "--json")
            self.assertEqual(info["footprints"].get("lobes_per_tile", 0), int(lobes), info["footprints"])

    def test_exact_levels(self):
        # A 64^2 map at R = 32 and sigma0 4: levels of 8 x 8 (256 KiB), 4 x 4 (64 KiB), ... centres.
        m = self.mapgen("flakes", "fl.png", "--size", "64", "--seed", "3")
        doc = self.run_json("tensorpack", m, "-o", self.path("e.gbk"), *PYRAMID, "--rank", "4", "--block", "16",
                            "--exact-levels", "0.1", schema="tensorpack.schema.json")
        levels = doc["levels"]
        self.assertGreaterEqual(len(levels), 2)
        for lv in levels:
            fits = lv["raw_bytes"] <= 0.1 * 1048576 and lv["level"] >= 1  # level 0 is the lobes'
            self.assertEqual(lv["exact"], fits, lv)
            if fits:
                self.assertLess(lv["relative_error"], 1e-5)
                self.assertEqual(lv["groups"], lv["blocks_kept"])
            else:
                self.assertGreater(lv["relative_error"], 1e-3)
        self.assertTrue(levels[0]["exact"] is False and levels[-1]["exact"] is True)
        self.assertEqual(doc["max_rank"], 16)
        self.assertEqual(doc["parameters"]["exact_levels_mib"], 0.1)
        # The exact levels are faithful. Above the first of them the bake measures the pyramid's
        # blend and the lobes (handover_probes, one per level from it while the lobes answer): the
        # lobes hand over at that level's sigma and the pyramid answers alone from sqrt(2) times
        # it, or, where the lobes answer above it (as on this flake map, whose few flakes a
        # footprint holds are glints), at sqrt(2) times the last level they answer above and the
        # pyramid from twice it.
        first = next(lv for lv in levels if lv["exact"])["sigma"]
        probes = doc["handover_probes"]
        self.assertGreaterEqual(len(probes), 1)
        self.assertAlmostEqual(probes[0]["sigma"], 2 ** 0.5 * first, places=6)
        for p in probes:
            lobes = p["lobes_error"] < p["blend_error"] and not (
                p["blend_error"] <= 0.04 and p["blend_error"] <= 0.2 * p["baseline"])
            self.assertEqual(p["answers"], "lobes" if lobes else "pyramid", p)
        for p in probes[:-1]:
            self.assertEqual(p["answers"], "lobes", probes)
        self.assertEqual(probes[0]["answers"], "lobes", probes)
        last = probes[-1]["sigma"] / 2 ** 0.5 if probes[-1]["answers"] == "lobes" else probes[-2]["sigma"] / 2 ** 0.5
        info = self.run_json("glintinfo", "info", self.path("e.gbk"), "--json")
        self.assertAlmostEqual(info["footprints"]["clustered_max_sigma"], 2 ** 0.5 * last, places=6)
        self.assertAlmostEqual(info["footprints"]["handover_max_sigma"], 2 * last, places=6)
        self.assertGreaterEqual(doc["gated_error"]["from_sigma"], first)
        for bad in ("-1", "2000", "nan"):
            self.assert_fails(clitest.BAD_ARGS, "tensorpack", m, "-o", self.path("x.gbk"), *PYRAMID,
                              "--exact-levels", bad, outputs=[self.path("x.gbk")])

    def test_bad_arguments(self):
        m = self.mapgen("beckmann", "m.png", "--size", "32")
        out = self.path("out.gbk")
        for args in (["--rank", "0"], ["--rank", "65"], ["--block", "12"], ["--method", "svd"],
                     ["--precision", "float8"], ["--error-target", "2"], ["--blank-threshold", "-1"]):
            self.assert_fails(clitest.BAD_ARGS, "tensorpack", *NOEXACT, m, "-o", out, *PYRAMID, "--quiet", *args, outputs=[out])

    def test_bad_inputs(self):
        out = self.path("out.gbk")
        self.assert_fails(clitest.IO, "tensorpack", *NOEXACT, self.path("missing.png"), "-o", out, *PACK, outputs=[out])
        # Every block blank: no block of a normalised NDF image carries the whole mass.
        m = self.mapgen("beckmann", "m.png", "--size", "32")
        err = self.assert_fails(clitest.INVALID, "tensorpack", *NOEXACT, m, "-o", out, *PYRAMID, *PACK,
                                "--blank-threshold", "1", outputs=[out])
        self.assertIn("blank", err)
        # A corrupt container: one byte flipped inside a chunk.
        pyramid = self.path("p.gbk")
        self.run_ok("ndfgen", m, "-o", pyramid, *PYRAMID, "--quiet")
        corrupt = self.path("corrupt.gbk")
        shutil.copy(pyramid, corrupt)
        with open(corrupt, "r+b") as f:
            f.seek(300)
            byte = f.read(1)
            f.seek(300)
            f.write(bytes([byte[0] ^ 0x5A]))
        self.assert_fails(clitest.INVALID, "tensorpack", *NOEXACT, corrupt, "-o", out, *PACK, outputs=[out])
        # A truncated container.
        truncated = self.path("trunc.gbk")
        with open(pyramid, "rb") as f:
            data = f.read()
        with open(truncated, "wb") as f:
            f.write(data[: len(data) // 2])
        self.assert_fails(clitest.INVALID, "tensorpack", *NOEXACT, truncated, "-o", out, *PACK, outputs=[out])
        # A container of another kind.
        tensor = self.path("t.gbk")
        self.run_ok("tensorpack", *NOEXACT, pyramid, "-o", tensor, *PACK)
        self.assert_fails(clitest.INVALID, "tensorpack", *NOEXACT, tensor, "-o", out, *PACK, outputs=[out])


if __name__ == "__main__":
    clitest.main()
