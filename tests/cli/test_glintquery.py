# SPDX-License-Identifier: Apache-2.0
"""glintquery: point, image and batch queries on ndf-pyramid and tensor-ndf assets through the runtime."""

import json
import math
import os
import subprocess
import tempfile

import clitest
from clitest import ToolTestCase, run


class GlintQuery(ToolTestCase):
    @classmethod
    def setUpClass(cls):
        # One asset shared by every test (each tool start costs about half a second).
        cls._assets = tempfile.TemporaryDirectory(prefix="glintbake-query-")
        m = os.path.join(cls._assets.name, "m.png")
        cls.asset = os.path.join(cls._assets.name, "m.gbk")
        for args in (("mapgen", "beckmann", "-o", m, "--size", "32", "--seed", "5", "--quiet"),
                     ("ndfgen", m, "-o", cls.asset, "--ndf-res", "32", "--stride", "8", "--sigma0", "4",
                      "--levels", "3", "--quiet")):
            code, _, err = run(*args)
            if code != 0:
                raise RuntimeError(f"{args[0]} failed: {err}")

    @classmethod
    def tearDownClass(cls):
        cls._assets.cleanup()

    def test_point(self):
        doc = self.run_json("glintquery", "point", self.asset, "--at", "12,20", "--sigma", "5", "--s", "0.02,-0.01",
                            schema="glintquery-point.schema.json")
        self.assertGreater(doc["value"], 0.0)
        out, _ = self.run_ok("glintquery", "point", self.asset, "--at", "12,20", "--sigma", "5", "--s", "0.02,-0.01")
        self.assertAlmostEqual(float(out), doc["value"], delta=1e-6 * doc["value"])
        # Outside the s-plane square: zero.
        doc = self.run_json("glintquery", "point", self.asset, "--at", "1,1", "--sigma", "4", "--s", "1.5,0",
                            schema="glintquery-point.schema.json")
        self.assertEqual(doc["value"], 0.0)

    def test_image(self):
        for name in ("ndf.exr", "ndf.png"):
            out = self.path(name)
            doc = self.run_json("glintquery", "image", self.asset, "--at", "16,16", "--sigma", "8", "-o", out,
                                schema="glintquery-image.schema.json")
            self.assertTrue(os.path.exists(out))
            self.assertEqual(doc["resolution"], 32)
            self.assertAlmostEqual(doc["mass"], 1.0, delta=2e-3)

    def test_image_preview(self):
        # --preview writes the PNG a second run with -o .png --scale writes, from one evaluation.
        exr, png, alone = self.path("p.exr"), self.path("p.png"), self.path("alone.png")
        at = ["--at", "16,16", "--sigma", "8"]
        doc = self.run_json("glintquery", "image", self.asset, *at, "-o", exr, "--preview", png, "--preview-scale",
                            "0.25", schema="glintquery-image.schema.json")
        self.assertEqual(doc["scale"], 1.0)
        self.assertEqual(doc["preview"], {"name": "p.png", "scale": 0.25})
        self.run_ok("glintquery", "image", self.asset, *at, "-o", alone, "--scale", "0.25", "--quiet")
        with open(png, "rb") as f, open(alone, "rb") as g:
            self.assertEqual(f.read(), g.read())
        doc = self.run_json("glintquery", "image", self.asset, *at, "-o", exr, "--preview", png)
        self.assertAlmostEqual(doc["preview"]["scale"] * doc["max"], 1.0, places=12)
        for bad in (["--preview", self.path("p.jpg")], ["--preview-scale", "2"], ["--preview", png, "--preview-scale",
                                                                                  "-1"]):
            self.assert_fails(clitest.BAD_ARGS, "glintquery", "image", self.asset, *at, "-o", self.path("n.exr"), *bad,
                              outputs=[self.path("n.exr")])

    def test_batch(self):
        queries = [
            {"op": "point", "x": 3.0, "y": 4.0, "sigma": 6.0, "s": [0.0, 0.0], "id": 1},
            {"op": "range", "x": 3.0, "y": 4.0, "sigma": 6.0, "rect": [-1, -1, 1, 1]},
            {"op": "sample", "x": 3.0, "y": 4.0, "sigma": 6.0, "u": [0.25, 0.75]},
            {"op": "pdf", "x": 3.0, "y": 4.0, "sigma": 6.0, "s": [0.01, 0.02]},
        ]
        code, out, err = run("glintquery", "batch", self.asset, stdin="\n".join(json.dumps(q) for q in queries) + "\n")
        self.assertEqual(code, 0, err)
        lines = [json.loads(l) for l in out.splitlines()]
        self.assertEqual(len(lines), 4)
        for l in lines:
            clitest.validate(l, "glintquery-batch.schema.json")
        self.assertEqual(lines[0]["id"], 1)
        # The whole-plane average is the mass / 4.
        self.assertAlmostEqual(lines[1]["value"] * 4.0, 1.0, delta=2e-3)
        # The sample's pdf equals the pdf query at the sampled point.
        s = lines[2]["s"]
        code, out, err = run("glintquery", "batch", self.asset,
                             stdin=json.dumps({"op": "pdf", "x": 3.0, "y": 4.0, "sigma": 6.0, "s": s}) + "\n")
        self.assertEqual(code, 0, err)
        self.assertAlmostEqual(json.loads(out)["value"], lines[2]["pdf"], delta=1e-9 * lines[2]["pdf"])

    def test_batch_range_pdf_mass(self):
        fp = {"x": 10.5, "y": 27.0, "sigma": 7.0}
        queries = [
            dict(fp, op="range", s0=[-0.3, -0.2], s1=[0.25, 0.4], id="r"),
            dict(fp, op="range", rect=[-0.3, -0.2, 0.25, 0.4]),
            dict(fp, op="mass"),
            dict(fp, op="sample", u=[0.6, 0.1]),
            dict(fp, op="range", s0=[0.3, 0.0], s1=[0.1, 0.5]),  # s0 > s1: an error line
            dict(fp, op="sample", u=[1.0, 0.5]),                 # u outside [0, 1): an error line
        ]
        code, out, err = run("glintquery", "batch", self.asset, stdin="\n".join(json.dumps(q) for q in queries) + "\n")
        self.assertEqual(code, clitest.INVALID)
        self.assertIn("2 of 6 queries failed", err)
        lines = [json.loads(l) for l in out.splitlines()]
        self.assertEqual(len(lines), 6)
        for l in lines:
            clitest.validate(l, "glintquery-batch.schema.json")
        self.assertEqual(lines[0]["id"], "r")
        self.assertEqual(lines[0]["average"], lines[1]["average"])
        self.assertGreater(lines[0]["average"], 0.0)
        self.assertAlmostEqual(lines[2]["mass"], 1.0, delta=2e-3)
        self.assertIn("error", lines[4])
        self.assertIn("error", lines[5])
        # pdf at the sample is the sample's pdf, exactly; with mass ~1 it is the point value too.
        s = lines[3]["s"]
        code, out, err = run("glintquery", "batch", self.asset,
                             stdin=json.dumps(dict(fp, op="pdf", s=s)) + "\n" + json.dumps(dict(fp, op="point", s=s)))
        self.assertEqual(code, 0, err)
        pdf, point = [json.loads(l) for l in out.splitlines()]
        self.assertEqual(pdf["pdf"], lines[3]["pdf"])
        self.assertAlmostEqual(point["value"], pdf["pdf"] * lines[2]["mass"], delta=1e-9 * point["value"])

    def test_tensor_asset(self):
        tensor = self.path("t.gbk")
        self.run_ok("tensorpack", self.asset, "-o", tensor, "--rank", "16", "--block", "16", "--nonneg", "--quiet")
        doc = self.run_json("glintquery", "point", tensor, "--at", "12,20", "--sigma", "5", "--s", "0.02,-0.01",
                            schema="glintquery-point.schema.json")
        self.assertEqual(doc["kind"], "tensor-ndf")
        ref = self.run_json("glintquery", "point", self.asset, "--at", "12,20", "--sigma", "5", "--s", "0.02,-0.01",
                            schema="glintquery-point.schema.json")
        self.assertEqual(ref["kind"], "ndf-pyramid")
        self.assertGreater(doc["value"], 0.0)
        # Point values of a rank-16 model carry its per-bin error; averages over many bins agree closely.
        wide = json.dumps({"op": "range", "x": 12, "y": 20, "sigma": 5, "s0": [-0.4, -0.4], "s1": [0.4, 0.4]}) + "\n"
        averages = []
        for path in (tensor, self.asset):
            code, out, err = run("glintquery", "batch", path, stdin=wide)
            self.assertEqual(code, 0, err)
            averages.append(json.loads(out)["average"])
        self.assertAlmostEqual(averages[0], averages[1], delta=0.02 * averages[1])
        img = self.run_json("glintquery", "image", tensor, "--at", "16,16", "--sigma", "8", "-o", self.path("t.exr"),
                            schema="glintquery-image.schema.json")
        self.assertEqual(img["resolution"], 32)
        self.assertAlmostEqual(img["mass"], 1.0, delta=3e-2)  # a 32^2 image of a rank-16 model of a 32^2 map
        fp = {"x": 3.0, "y": 4.0, "sigma": 6.0}
        queries = [dict(fp, op="sample", u=[k / 7.0, (k * 3 % 7) / 7.0]) for k in range(7)]
        queries += [dict(fp, op="range", s0=[-1, -1], s1=[1, 1]), dict(fp, op="mass")]
        code, out, err = run("glintquery", "batch", tensor, stdin="\n".join(json.dumps(q) for q in queries) + "\n")
        self.assertEqual(code, 0, err)
        lines = [json.loads(l) for l in out.splitlines()]
        for l in lines:
            clitest.validate(l, "glintquery-batch.schema.json")
        self.assertAlmostEqual(lines[7]["average"] * 4.0, lines[8]["mass"], delta=1e-4)
        pdf_queries = [dict(fp, op="pdf", s=l["s"]) for l in lines[:7]]
        code, out, err = run("glintquery", "batch", tensor, stdin="\n".join(json.dumps(q) for q in pdf_queries) + "\n")
        self.assertEqual(code, 0, err)
        for sample, answer in zip(lines[:7], [json.loads(l) for l in out.splitlines()]):
            self.assertEqual(answer["pdf"], sample["pdf"])

    def test_batch_bad_lines(self):
        code, out, err = run("glintquery", "batch", self.asset,
                             stdin='{"op":"point","x":1,"y":1,"sigma":2,"s":[0,0]}\nnot json\n{"op":"warp"}\n')
        self.assertEqual(code, clitest.INVALID)
        lines = [json.loads(l) for l in out.splitlines()]
        self.assertEqual(len(lines), 3)
        self.assertIn("value", lines[0])
        self.assertIn("error", lines[1])
        self.assertIn("error", lines[2])
        self.assertEqual(len([l for l in err.splitlines() if l.strip()]), 1)

    def test_batch_hostile_lines(self):
        # A deeply nested id and invalid UTF-8 each cost one error object (or a replaced character),
        # never the whole batch.
        deep = '{"op":"mass","x":1,"y":1,"sigma":2,"id":' + "[" * 100000 + "]" * 100000 + "}"
        utf8 = b'{"op":"mass","x":1,"y":1,"sigma":2,"id":"\xff\xfe"}'
        good = b'{"op":"mass","x":1,"y":1,"sigma":2}'
        stdin = deep.encode() + b"\n" + utf8 + b"\n" + good + b"\n"
        proc = subprocess.run([clitest.tool_path("glintquery"), "batch", self.asset], input=stdin, capture_output=True,
                              timeout=120)
        self.assertEqual(proc.returncode, clitest.INVALID)
        lines = [json.loads(l) for l in proc.stdout.decode("utf-8").splitlines()]
        self.assertEqual(len(lines), 3)
        self.assertIn("nested deeper than 64", lines[0]["error"])
        self.assertTrue("mass" in lines[1] or "error" in lines[1])
        self.assertIn("mass", lines[2])

    def test_errors(self):
        self.assert_fails(clitest.IO, "glintquery", "point", self.path("none.gbk"), "--at", "1,1", "--sigma", "1",
                          "--s", "0,0")
        bad = self.path("bad.gbk")
        with open(bad, "wb") as f:
            f.write(b"not a container at all" * 10)
        self.assert_fails(clitest.INVALID, "glintquery", "point", bad, "--at", "1,1", "--sigma", "1", "--s", "0,0")
        self.assert_fails(clitest.BAD_ARGS, "glintquery", "point", self.asset, "--at", "1", "--sigma", "1",
                          "--s", "0,0")
        self.assert_fails(clitest.BAD_ARGS, "glintquery", "point", self.asset, "--at", "1,1", "--sigma", "-1",
                          "--s", "0,0")
        self.assert_fails(clitest.BAD_ARGS, "glintquery")
        out = self.path("x.png")
        self.assert_fails(clitest.IO, "glintquery", "image", self.asset, "--at", "1,1", "--sigma", "1",
                          "-o", self.path("no/dir/x.png"))
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    clitest.main()
