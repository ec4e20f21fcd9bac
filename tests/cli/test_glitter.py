# SPDX-License-Identifier: Apache-2.0
"""Procedural glitter: glintref glitter and tensorpack --procedural glitter (schema-valid --json, hierarchy equal to explicit
enumeration, D near the smooth NDF for large N, the same answer twice) and ndfgen --procedural
glitter (a pyramid glintinfo validates and glintquery reads, a glitter asset, byte-identical for
-j1 and -j2, one-line errors with exit 1 for bad parameters and nothing left behind)."""

import math
import os
import struct

import clitest
from clitest import INVALID, ToolTestCase
from containers import SECTION_METADATA, build_container, metadata

KIND_GLITTER, SECTION_GLITTER_INFO, SECTION_GLITTER_INTEGRALS = 7, 128, 129


def glitter_record(alpha=0.2, integral_count=4, particles=100000):
    """A GlitterRecord (formats/SPEC.md 10.6, 80 bytes): Beckmann, depth 20, 64 x 64 texels, R 32."""
    return struct.pack("<4I2Q2d4I2d", 0x544C4747, 1, 0, 20, particles, 7, alpha, math.radians(1.0), 64, 64, 32,
                       integral_count, 1e-4, 9.5699e-4)


def integral_table(entries=4):
    """Root triangles only (no tabulated children): each a quarter of the isotropic NDF's mass."""
    return b"".join(struct.pack("<dII", 1.0 / entries, 0, 0) for _ in range(entries))

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
        q = self.run_json("glintquery", "point", out, "--at", "20,30", "--sigma", "8", "--s", "0.1,0.1",
                          schema="glintquery-point.schema.json")
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
        q = self.run_json("glintquery", "point", asset, "--at", "20,30", "--sigma", "2", "--s", "0.1,0.1",
                          schema="glintquery-point.schema.json")
        self.assertEqual(q["kind"], "glitter")
        self.assertGreaterEqual(q["value"], 0.0)

    def test_validate_checks_the_glitter_layout(self):
        """glintinfo validate runs the glitter record and table checks the runtime's loader runs (error
        6007), and passes exactly the glitter files the runtime opens (6004 otherwise)."""
        meta = (SECTION_METADATA, 0, metadata(asset_kind="glitter"))
        def asset(name, *sections):
            return self.write(name, build_container(list(sections) + [meta], kind=KIND_GLITTER))
        good = asset("good.gbk", (SECTION_GLITTER_INFO, 0, glitter_record()),
                     (SECTION_GLITTER_INTEGRALS, 0, integral_table()))
        self.run_ok("glintinfo", "validate", good)
        q = self.run_json("glintquery", "point", good, "--at", "20,30", "--sigma", "2", "--s", "0.1,0.1")
        self.assertGreaterEqual(q["value"], 0.0)
        cases = {
            "nan_alpha": [(SECTION_GLITTER_INFO, 0, glitter_record(alpha=float("nan"))),
                          (SECTION_GLITTER_INTEGRALS, 0, integral_table())],
            "no_particles": [(SECTION_GLITTER_INFO, 0, glitter_record(particles=0)),
                             (SECTION_GLITTER_INTEGRALS, 0, integral_table())],
            "short_record": [(SECTION_GLITTER_INFO, 0, glitter_record()[:72]),
                             (SECTION_GLITTER_INTEGRALS, 0, integral_table())],
            "count_mismatch": [(SECTION_GLITTER_INFO, 0, glitter_record(integral_count=8)),
                               (SECTION_GLITTER_INTEGRALS, 0, integral_table())],
            "bad_table": [(SECTION_GLITTER_INFO, 0, glitter_record()),
                          (SECTION_GLITTER_INTEGRALS, 0, struct.pack("<dII", -1.0, 0, 0) * 4)],
            "ragged_table": [(SECTION_GLITTER_INFO, 0, glitter_record()),
                             (SECTION_GLITTER_INTEGRALS, 0, integral_table() + b"\0" * 8)],
            "record_key_1": [(SECTION_GLITTER_INFO, 1, glitter_record()),
                             (SECTION_GLITTER_INTEGRALS, 0, integral_table())],
            "no_table": [(SECTION_GLITTER_INFO, 0, glitter_record())],
            "no_record": [(SECTION_GLITTER_INTEGRALS, 0, integral_table())],
            "two_records": [(SECTION_GLITTER_INFO, 0, glitter_record()), (SECTION_GLITTER_INFO, 1, glitter_record()),
                            (SECTION_GLITTER_INTEGRALS, 0, integral_table())],
        }
        for name, sections in cases.items():
            with self.subTest(name):
                path = asset(name + ".gbk", *sections)
                err = self.assert_fails(INVALID, "glintinfo", "validate", path)
                self.assertIn("error-6007", err)
                # The runtime refuses every one of them too.
                code, _, _ = clitest.run("glintquery", "point", path, "--at", "1,1", "--sigma", "1", "--s", "0,0")
                self.assertNotEqual(code, 0)

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
