# SPDX-License-Identifier: Apache-2.0
"""Sharded bakes: ndfgen --shard I/N writes partial containers that glintinfo merge joins into the
asset one machine bakes, byte for byte, for several shard counts; parts that do not belong
together (missing, twice, another bake) are refused with one-line errors and no output; a partial
is never taken for an asset."""

import json
import os

import clitest
from clitest import ToolTestCase, run

SMALL = ["--ndf-res", "16", "--stride", "4", "--sigma0", "2", "--region", "2", "--quiet"]
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
