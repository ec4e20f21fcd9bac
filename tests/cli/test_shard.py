# SPDX-License-Identifier: Apache-2.0
"""Sharded bakes: ndfgen and tensorpack --shard I/N write partial containers that glintinfo merge
joins into the asset one machine bakes, byte for byte, for several shard counts; parts that do not
belong together (missing, twice, another bake) are refused with one-line errors and no output; a
partial is never taken for an asset."""

import json
import os

import clitest
from clitest import ToolTestCase, run

SMALL = ["--ndf-res", "16", "--stride", "4", "--sigma0", "2", "--region", "2", "--quiet"]
# tensorpack on the same small pyramids: blocks of 8 bins, rank 4 (levels of at most 256 centres
# above level 0 are stored exactly by default).
PACK = SMALL + ["--block", "8", "--rank", "4"]
# wangtile: 16 tiles of 16 texels, small pyramids.
WANG = ["--tile-size", "16", "--ndf-res", "16", "--block", "8", "--sigma0", "1", "--stride", "2", "--rank", "4",
        "--max-iters", "20", "--quiet"]
INVALID_INPUT = 3


class Shards(ToolTestCase):
    def bake_shards(self, tool, inputs, n, stem, *args):
        parts = []
        for i in range(n):
            part = self.path(f"{stem}.{i}of{n}.part.gbk")
            self.run_ok(tool, *inputs, "-o", part, "--shard", f"{i}/{n}", *args)
            parts.append(part)
        return parts

    def test_ndfgen_merge_is_byte_identical(self):
        m = self.mapgen("beckmann", "s.png", "--size", "48", "--seed", "5")
        local = self.path("local.gbk")
        # A tight convergence threshold: the automatic level count probes and keeps several levels.
        args = SMALL + ["--converge-mse", "1e-4"]
        doc = self.run_json("ndfgen", m, "-o", local, *args)
        self.assertGreaterEqual(len(doc["levels"]), 3)
        self.assertEqual(doc["stop_reason"], "converged")
        for n in (1, 2, 3, 7):
            parts = self.bake_shards("ndfgen", [m], n, "s", *args)
            merged = self.path(f"merged{n}.gbk")
            # Any order of the parts.
            self.run_ok("glintinfo", "merge", *reversed(parts), "-o", merged, "--quiet")
            self.assertEqual(clitest.file_hash(merged), clitest.file_hash(local), f"{n} shards")
            for p in parts:
                code, out, err = run("glintinfo", "validate", p)
                self.assertEqual(code, 0, err)

    def test_explicit_levels_and_no_flakes(self):
        m = self.mapgen("beckmann", "b.png", "--size", "40", "--seed", "2")
        args = SMALL + ["--levels", "3", "--no-flakes"]
        local = self.path("local.gbk")
        self.run_ok("ndfgen", m, "-o", local, *args)
        parts = self.bake_shards("ndfgen", [m], 3, "b", *args)
        merged = self.path("merged.gbk")
        self.run_ok("glintinfo", "merge", *parts, "-o", merged, "--quiet")
        self.assertEqual(clitest.file_hash(merged), clitest.file_hash(local))

    def test_shard_json_and_merge_json(self):
        m = self.mapgen("flakes", "f.png", "--size", "32")
        part = self.path("f.part.gbk")
        doc = self.run_json("ndfgen", m, "-o", part, "--shard", "0/1", *SMALL, schema="shard.schema.json")
        self.assertEqual(doc["shard"], {"index": 0, "count": 1})
        self.assertEqual(doc["units"], doc["units_total"])
        out = self.path("f.gbk")
        doc = self.run_json("glintinfo", "merge", part, "-o", out, schema="glintinfo-merge.schema.json")
        self.assertEqual(doc["asset_kind"], "ndf-pyramid")
        self.assertEqual(doc["file_bytes"], os.path.getsize(out))
        code, info, err = run("glintinfo", "info", part, "--json")
        self.assertEqual(code, 0, err)
        self.assertEqual(json.loads(info)["asset_kind"], "partial")

    def test_parts_that_do_not_belong_together(self):
        m = self.mapgen("scratches", "s.png", "--size", "32", "--seed", "1")
        other = self.mapgen("scratches", "o.png", "--size", "32", "--seed", "2")
        parts = self.bake_shards("ndfgen", [m], 3, "s", *SMALL)
        out = self.path("out.gbk")
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], parts[2], "-o", out, outputs=[out])
        self.assertIn("shard 1/3 missing", err)
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], parts[1], parts[1], parts[2], "-o",
                                out, outputs=[out])
        self.assertIn("given twice", err)
        foreign = self.bake_shards("ndfgen", [other], 3, "o", *SMALL)
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], foreign[1], parts[2], "-o", out,
                                outputs=[out])
        self.assertIn("different inputs", err)
        options = self.bake_shards("ndfgen", [m], 3, "r", *SMALL, "--sigma-r", "0.05")
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], options[1], parts[2], "-o", out,
                                outputs=[out])
        self.assertIn("different options", err)
        four = self.bake_shards("ndfgen", [m], 4, "q", *SMALL)
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], four[1], parts[2], "-o", out,
                                outputs=[out])
        self.assertIn("shard counts", err)
        local = self.path("local.gbk")
        self.run_ok("ndfgen", m, "-o", local, *SMALL)
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", local, "-o", out, outputs=[out])
        self.assertIn("not a partial container", err)

    def merge_matches(self, parts, local, label):
        merged = self.path("merged.gbk")
        if os.path.exists(merged):
            os.remove(merged)
        self.run_ok("glintinfo", "merge", *reversed(parts), "-o", merged, "--quiet")
        self.assertEqual(clitest.file_hash(merged), clitest.file_hash(local), label)

    def test_tensorpack_merge_is_byte_identical(self):
        m = self.mapgen("scratches", "t.png", "--size", "48", "--seed", "3")
        local = self.path("local.gbk")
        args = PACK + ["--converge-mse", "1e-4"]
        doc = self.run_json("tensorpack", m, "-o", local, *args)
        self.assertGreaterEqual(len(doc["levels"]), 3)
        self.assertTrue(any(level["exact"] for level in doc["levels"]))
        for n in (1, 2, 3, 7):
            parts = self.bake_shards("tensorpack", [m], n, "t", *args)
            self.merge_matches(parts, local, f"{n} shards")
            for p in parts if n == 3 else []:
                code, out, err = run("glintinfo", "validate", p)
                self.assertEqual(code, 0, err)
        # Shards at another thread count give the same parts.
        again = self.bake_shards("tensorpack", [m], 2, "j1", *args, "-j", "1")
        first = [self.path(f"t.{i}of2.part.gbk") for i in range(2)]
        for a, b in zip(first, again):
            self.assertEqual(clitest.file_hash(a), clitest.file_hash(b))

    def test_tensorpack_variants(self):
        # Every level compressed, an error target (ranks per group), float16 factors, no flakes, and
        # a map with blank regions (a flat map's spikes leave most blocks blank).
        m = self.mapgen("flakes", "v.png", "--size", "40", "--seed", "4")
        flat = self.mapgen("flat", "flat.png", "--size", "24")
        cases = [
            (m, ["--exact-levels", "0", "--error-target", "0.2", "--precision", "float16"]),
            (m, ["--levels", "2", "--no-flakes", "--lobes", "0"]),
            (flat, ["--exact-levels", "0"]),
        ]
        for k, (src, extra) in enumerate(cases):
            local = self.path(f"local{k}.gbk")
            self.run_ok("tensorpack", src, "-o", local, *PACK, *extra)
            parts = self.bake_shards("tensorpack", [src], 3, f"v{k}", *PACK, *extra)
            self.merge_matches(parts, local, " ".join(extra))
        # The shard's --json summary, and the merge's.
        part = self.path("j.part.gbk")
        doc = self.run_json("tensorpack", flat, "-o", part, "--shard", "0/1", *PACK, schema="shard.schema.json")
        self.assertEqual(doc["shard"], {"index": 0, "count": 1})
        self.assertEqual(doc["units"], doc["units_total"])
        doc = self.run_json("glintinfo", "merge", part, "-o", self.path("j.gbk"), schema="glintinfo-merge.schema.json")
        self.assertEqual(doc["asset_kind"], "tensor-ndf")
        self.assertEqual(doc["file_bytes"], os.path.getsize(self.path("j.gbk")))

    def test_tensorpack_max_error_gate_applies_at_the_merge(self):
        m = self.mapgen("flakes", "g.png", "--size", "32", "--seed", "6")
        args = PACK + ["--exact-levels", "0", "--lobes", "0", "--max-error", "0.0001"]
        out = self.path("g.gbk")
        self.assert_fails(4, "tensorpack", m, "-o", out, *args, outputs=[out])
        parts = self.bake_shards("tensorpack", [m], 2, "g", *args)
        err = self.assert_fails(4, "glintinfo", "merge", *parts, "-o", out, outputs=[out])
        self.assertIn("--max-error", err)

    def test_tensorpack_parts_that_do_not_belong_together(self):
        m = self.mapgen("scratches", "s.png", "--size", "32", "--seed", "1")
        parts = self.bake_shards("tensorpack", [m], 3, "s", *PACK)
        out = self.path("out.gbk")
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], parts[2], "-o", out, outputs=[out])
        self.assertIn("shard 1/3 missing", err)
        self.assertEqual(len(err.strip().splitlines()), 1)
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], parts[1], parts[1], parts[2], "-o",
                                out, outputs=[out])
        self.assertIn("given twice", err)
        options = self.bake_shards("tensorpack", [m], 3, "r", *PACK[:-1], "3")
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], options[1], parts[2], "-o", out,
                                outputs=[out])
        self.assertIn("different options", err)
        pyramid = self.bake_shards("ndfgen", [m], 3, "p", *SMALL)
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], pyramid[1], parts[2], "-o", out,
                                outputs=[out])
        self.assertIn("different tools", err)
        # Not for containers or procedural surfaces.
        pyr = self.path("pyr.gbk")
        self.run_ok("ndfgen", m, "-o", pyr, *SMALL)
        self.assert_fails(5, "tensorpack", pyr, "-o", out, "--shard", "0/2", "--block", "8", "--rank", "4", "--quiet",
                          outputs=[out])

    def test_wangtile_merge_is_byte_identical(self):
        ex = self.mapgen("beckmann", "w.png", "--size", "48", "--alpha", "0.3")
        local = self.path("local.gbk")
        self.run_ok("wangtile", ex, "-o", local, *WANG)
        for n in (1, 2, 3, 7):
            parts = self.bake_shards("wangtile", [ex], n, "w", *WANG)
            self.merge_matches(parts, local, f"{n} shards")
        # Uncompressed tiles, and more shards than tiles would leave some shards empty.
        local = self.path("local_u.gbk")
        self.run_ok("wangtile", ex, "-o", local, "--uncompressed", *WANG)
        parts = self.bake_shards("wangtile", [ex], 3, "u", "--uncompressed", *WANG)
        self.merge_matches(parts, local, "uncompressed")
        doc = self.run_json("wangtile", ex, "-o", self.path("w.part.gbk"), "--shard", "2/3", "--uncompressed", *WANG,
                            schema="shard.schema.json")
        self.assertEqual(doc["units_total"], 16)
        out = self.path("x.part.gbk")
        self.assert_fails(1, "wangtile", ex, "-o", out, "--shard", "0/2", "--atlas", self.path("a.exr"), *WANG,
                          outputs=[out])
        err = self.assert_fails(INVALID_INPUT, "glintinfo", "merge", parts[0], parts[2], "-o", out, outputs=[out])
        self.assertIn("shard 1/3 missing", err)

    def test_bad_shard_option(self):
        m = self.mapgen("beckmann", "b.png", "--size", "16")
        out = self.path("b.part.gbk")
        for bad in ("3/3", "1", "a/b", "-1/2", "0/0"):
            err = self.assert_fails(1, "ndfgen", m, "-o", out, "--shard", bad, *SMALL, outputs=[out])
            self.assertIn("--shard", err)

    def test_runtime_refuses_a_partial(self):
        m = self.mapgen("beckmann", "b.png", "--size", "16")
        part = self.path("b.part.gbk")
        self.run_ok("ndfgen", m, "-o", part, "--shard", "0/2", *SMALL)
        code, out, err = run("glintquery", "point", part, "--at", "8,8", "--sigma", "2", "--s", "0,0")
        self.assertNotEqual(code, 0)
        self.assertIn("glintinfo merge", err)


if __name__ == "__main__":
    clitest.main()
