# SPDX-License-Identifier: Apache-2.0
"""Procedural glitter: glintref glitter and tensorpack --procedural glitter (schema-valid --json, hierarchy equal to explicit
enumeration, D near the smooth NDF for large N, the same answer twice) and ndfgen --procedural
glitter (a pyramid glintinfo validates and glintquery reads, a glitter asset, byte-identical for
-j1 and -j2, one-line errors with exit 1 for bad parameters and nothing left behind)."""

import os

import clitest
from clitest import ToolTestCase

QUERY = ["--alpha", "0.3", "--at", "0.4,0.7", "--extent", "0.2", "--s", "0.1,-0.05", "--gamma", "4"]


class Glitter(ToolTestCase):
    def test_glintref_glitter_json_and_enumeration(self):
        doc = self.run_json("glintref", "glitter", "--particles", "20000", *QUERY, "--exact", "--enumerate",
                            schema="glintref-glitter.schema.json")
        self.assertEqual(doc["command"], "glitter")
        self.assertEqual(doc["count"], doc["enumerated_count"])
        self.assertFalse(doc["early_stop"])
        again = self.run_json("glintref", "glitter", "--particles", "20000", *QUERY, "--exact", "--enumerate")
        self.assertEqual(again["count"], doc["count"])
        out, _ = self.run_ok("glintref", "glitter", "--particles", "20000", *QUERY)
        self.assertTrue(out.startswith("count "))

    def test_glintref_glitter_converges(self):
        doc = self.run_json("glintref", "glitter", "--particles", "1000000000", *QUERY,
                            schema="glintref-glitter.schema.json")
        self.assertIsNone(doc["enumerated_count"])
        self.assertAlmostEqual(doc["D"] / doc["smooth_D"], 1.0, delta=0.03)
        self.assertLess(doc["nodes"], 1000000)

    def test_glintref_glitter_bad_arguments(self):
        for bad in (["--particles", "0"], ["--particles", "-5"], ["--particles", "100", "--alpha", "0"],
                    ["--particles", "100", "--alpha", "-1"], ["--particles", "100", "--extent", "2"],
                    ["--particles", "100", "--gamma", "90"], ["--particles", "100", "--s", "1,1"],
                    ["--particles", "100000000", "--enumerate"], ["--particles", "100", "--distribution", "phong"]):
            # Options given twice: CLI11 keeps the last, so these override QUERY.
            self.assert_fails(1, "glintref", "glitter", *QUERY, *bad)

    def test_ndfgen_procedural_pyramid_and_asset(self):
        out = self.path("g.gbk")
        doc = self.run_json("ndfgen", "--procedural", "glitter", "--particles", "200000", "--alpha", "0.3",
                            "--size", "64,64", "--ndf-res", "16", "--stride", "16", "--sigma0", "8", "-o", out,
                            "--quiet", schema="ndfgen-procedural.schema.json")
        self.assertEqual(doc["kind"], "ndf-pyramid")
        self.assertGreaterEqual(len(doc["levels"]), 1)
        self.run_ok("glintinfo", "validate", out)
        q = self.run_json("glintquery", "point", out, "--at", "20,30", "--sigma", "8", "--s", "0.1,0.1")
        self.assertGreaterEqual(q["value"], 0.0)
        # Deterministic for every thread count.
        out1 = self.path("g1.gbk")
        self.run_ok("ndfgen", "--procedural", "glitter", "--particles", "200000", "--alpha", "0.3", "--size", "64,64",
                    "--ndf-res", "16", "--stride", "16", "--sigma0", "8", "-o", out1, "--quiet", "-j1")
        self.assertEqual(clitest.file_hash(out), clitest.file_hash(out1))
        asset = self.path("a.gbk")
        doc = self.run_json("ndfgen", "--procedural", "glitter", "--glitter-asset", "--particles", "200000",
                            "--alpha", "0.3", "--size", "64,64", "-o", asset, "--quiet",
                            schema="ndfgen-procedural.schema.json")
        self.assertEqual(doc["kind"], "glitter")
        self.run_ok("glintinfo", "validate", asset)
        q = self.run_json("glintquery", "point", asset, "--at", "20,30", "--sigma", "2", "--s", "0.1,0.1")
        self.assertGreaterEqual(q["value"], 0.0)

    def test_tensorpack_procedural(self):
        out = self.path("t.gbk")
        doc = self.run_json("tensorpack", "--procedural", "glitter", "--particles", "100000", "--alpha", "0.3",
                            "--size", "64,64", "--ndf-res", "16", "--block", "8", "--stride", "16", "--sigma0", "8",
                            "-o", out, "--quiet", schema="tensorpack.schema.json")
        self.assertEqual(doc["source"], "glitter")
        self.run_ok("glintinfo", "validate", out)
        self.assert_fails(1, "tensorpack", "--procedural", "glitter", "--alpha", "-1", "-o", out + "2",
                          outputs=[out + "2"])

    def test_ndfgen_procedural_bad_arguments(self):
        out = self.path("bad.gbk")
        base = ["ndfgen", "--procedural", "glitter", "-o", out]
        for bad in (["--particles", "0"], ["--alpha", "0"], ["--alpha", "-0.5"], ["--size", "0,10"],
                    ["--size", "100000,100000"], ["--size", "abc"], ["--distribution", "phong"]):
            self.assert_fails(1, *base, *bad, outputs=[out])
        self.assert_fails(1, "ndfgen", "--procedural", "noise", "-o", out, outputs=[out])
        self.assert_fails(1, "ndfgen", "-o", out, outputs=[out])


if __name__ == "__main__":
    clitest.main()
