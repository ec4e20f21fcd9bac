# SPDX-License-Identifier: Apache-2.0
"""glintbake bake: a manifest of assets baked by the tools as subprocesses. Outputs identical to
the tools run by hand (sharded ones too), incremental by content hash, tool version and options,
a failing asset reported with its exit code and no output while the others bake, one depfile,
schema-valid --json, manifest errors as one-line errors, and the Slurm scripts of --emit slurm."""

import json
import os

import clitest
from clitest import ToolTestCase, run

SMALL = {"ndf-res": 16, "stride": 4, "sigma0": 2, "region": 2}
SMALL_ARGS = ["--ndf-res", "16", "--region", "2", "--sigma0", "2", "--stride", "4"]
RUNTIME = 4


def read(path):
    with open(path) as f:
        return f.read()


class GlintBake(ToolTestCase):
    def write_manifest(self, assets, name="m.json", defaults=None):
        doc = {"schema": "glintbake.manifest/1", "defaults": defaults or {"tool": "ndfgen", "options": SMALL},
               "assets": assets}
        path = self.path(name)
        with open(path, "w") as f:
            json.dump(doc, f)
        return path

    def statuses(self, doc):
        return {a["name"]: a["status"] for a in doc["assets"]}

    def test_bake_incremental_and_identical(self):
        a = self.mapgen("beckmann", "a.png", "--size", "32", "--seed", "1")
        b = self.mapgen("scratches", "b.png", "--size", "32", "--seed", "2")
        c = self.mapgen("flakes", "c.png", "--size", "40", "--seed", "3")
        assets = [{"inputs": ["a.png"], "output": "out/a.gbk"},
                  {"inputs": ["b.png"], "output": "out/b.gbk", "options": {"levels": 2}},
                  {"name": "c", "inputs": ["c.png"], "output": "out/c.gbk", "shards": 3}]
        m = self.write_manifest(assets)
        doc = self.run_json("glintbake", "bake", m, "-j", "2", schema="glintbake-bake.schema.json")
        self.assertEqual(self.statuses(doc), {"a": "baked", "b": "baked", "c": "baked"})
        self.assertEqual(doc["failed"], 0)
        # The same bytes as the tools run by hand (the sharded asset as one machine bakes it).
        for src, out, extra in ((a, "a", []), (b, "b", ["--levels", "2"]), (c, "c", [])):
            ref = self.path(out + ".ref.gbk")
            self.run_ok("ndfgen", src, "-o", ref, *SMALL_ARGS, *extra, "--quiet")
            self.assertEqual(clitest.file_hash(ref), clitest.file_hash(self.path(f"out/{out}.gbk")), out)
        self.assertFalse(os.path.exists(self.path("out/c.gbk.shards")))
        # Nothing changed: nothing baked.
        doc = self.run_json("glintbake", "bake", m, schema="glintbake-bake.schema.json")
        self.assertEqual(doc["up_to_date"], 3)
        # An option change rebakes that asset only; so does new input content.
        assets[0]["options"] = {"sigma-r": 0.05}
        self.write_manifest(assets)
        self.mapgen("scratches", "b.png", "--size", "32", "--seed", "7")
        doc = self.run_json("glintbake", "bake", m)
        self.assertEqual(self.statuses(doc), {"a": "baked", "b": "baked", "c": "up-to-date"})
        # A damaged output is rebaked too.
        with open(self.path("out/c.gbk"), "ab") as f:
            f.write(b"x")
        doc = self.run_json("glintbake", "bake", m)
        self.assertEqual(self.statuses(doc)["c"], "baked")

    def test_failing_asset_does_not_stop_the_others(self):
        a = self.mapgen("beckmann", "a.png", "--size", "32")
        self.write("bad.png", b"not an image")
        assets = [{"name": "bad", "inputs": ["bad.png"], "output": "bad.gbk"},
                  {"name": "good", "inputs": ["a.png"], "output": "good.gbk"},
                  {"name": "badshards", "inputs": ["bad.png"], "output": "bs.gbk", "shards": 2}]
        m = self.write_manifest(assets)
        code, out, err = run("glintbake", "bake", m, "--json", "-j", "2")
        self.assertEqual(code, RUNTIME, err)
        doc = json.loads(out)
        clitest.validate(doc, "glintbake-bake.schema.json")
        by = {x["name"]: x for x in doc["assets"]}
        self.assertEqual(by["good"]["status"], "baked")
        self.assertEqual(by["bad"]["status"], "failed")
        self.assertIn(by["bad"]["exit_code"], (2, 3))
        self.assertIn("bad.png", by["bad"]["message"])
        self.assertEqual(by["badshards"]["status"], "failed")
        self.assertFalse(os.path.exists(self.path("bad.gbk")))
        self.assertFalse(os.path.exists(self.path("bs.gbk")))
        self.assertFalse(os.path.exists(self.path("bs.gbk.shards")))
        self.assertTrue(os.path.exists(self.path("good.gbk")))
        # The failed asset is retried on the next run; the good one is up to date.
        code, out, _ = run("glintbake", "bake", m, "--json")
        self.assertEqual(self.statuses(json.loads(out))["good"], "up-to-date")

    def test_depfile_lists_manifest_and_inputs(self):
        self.mapgen("beckmann", "a.png", "--size", "16")
        m = self.write_manifest([{"inputs": ["a.png"], "output": "a.gbk"}])
        dep = self.path("bake.d")
        self.run_ok("glintbake", "bake", m, "--depfile", dep, "--quiet")
        text = read(dep)
        self.assertIn("a.gbk:", text)
        self.assertIn("m.json", text)
        self.assertIn("a.png", text)

    def test_manifest_errors(self):
        bad = self.write("bad.json", b"{ not json")
        self.assert_fails(3, "glintbake", "bake", bad)
        self.assert_fails(2, "glintbake", "bake", self.path("missing.json"))
        m = self.write_manifest([{"tool": "nosuchtool", "output": "x.gbk"}])
        err = self.assert_fails(3, "glintbake", "bake", m)
        self.assertIn("assets[0]", err)
        m = self.write_manifest([{"output": "x.gbk", "options": {"o": "y.gbk"}}])
        self.assertIn("set by glintbake", self.assert_fails(3, "glintbake", "bake", m))
        m = self.write_manifest([{"tool": "mapgen", "args": ["flat"], "output": "x.exr", "shards": 2}])
        self.assertIn("--shard", self.assert_fails(3, "glintbake", "bake", m))
        m = self.write_manifest([{"output": "x.gbk"}, {"output": "x.gbk"}])
        self.assertIn("twice", self.assert_fails(3, "glintbake", "bake", m))

    def test_sharded_tensorpack_asset(self):
        t = self.mapgen("scratches", "t.png", "--size", "40", "--seed", "5")
        pack = {"block": 8, "rank": 4}
        m = self.write_manifest([{"name": "t", "tool": "tensorpack", "inputs": ["t.png"], "output": "out/t.gbk",
                                  "options": pack, "shards": 3}])
        doc = self.run_json("glintbake", "bake", m, "-j", "2", schema="glintbake-bake.schema.json")
        self.assertEqual(self.statuses(doc), {"t": "baked"})
        ref = self.path("t.ref.gbk")
        self.run_ok("tensorpack", t, "-o", ref, *SMALL_ARGS, "--block", "8", "--rank", "4", "--quiet")
        self.assertEqual(clitest.file_hash(ref), clitest.file_hash(self.path("out/t.gbk")))
        self.assertFalse(os.path.exists(self.path("out/t.gbk.shards")))
        jobs = self.path("jobs")
        os.remove(self.path("out/t.gbk"))
        doc = self.run_json("glintbake", "bake", m, "--emit", "slurm", "--emit-dir", jobs,
                            schema="glintbake-bake.schema.json")
        tasks = read(os.path.join(jobs, "tasks.txt")).splitlines()
        self.assertEqual(sum("tensorpack" in x and "--shard" in x for x in tasks), 3)

    def test_emit_slurm(self):
        self.mapgen("beckmann", "a.png", "--size", "16")
        self.mapgen("flakes", "b.png", "--size", "16")
        m = self.write_manifest([{"inputs": ["a.png"], "output": "a.gbk"},
                                 {"inputs": ["b.png"], "output": "b.gbk", "shards": 4}])
        jobs = self.path("jobs")
        doc = self.run_json("glintbake", "bake", m, "--emit", "slurm", "--emit-dir", jobs,
                            schema="glintbake-bake.schema.json")
        self.assertEqual(doc["tasks"], 5)
        tasks = read(os.path.join(jobs, "tasks.txt")).splitlines()
        self.assertEqual(len(tasks), 5)
        self.assertEqual(sum("--shard" in t for t in tasks), 4)
        sbatch = read(os.path.join(jobs, "bake.sbatch"))
        self.assertIn("#SBATCH --array=0-4", sbatch)
        self.assertIn("logs/task-%a.log", sbatch)
        merge = read(os.path.join(jobs, "merge.sbatch"))
        self.assertIn("glintinfo merge", merge.replace(os.path.dirname(clitest.tool_path("glintinfo")) + "/", ""))
        self.assertIn("--dependency=afterok", read(os.path.join(jobs, "submit.sh")))
        # Nothing is baked here.
        self.assertFalse(os.path.exists(self.path("a.gbk")))


if __name__ == "__main__":
    clitest.main()
