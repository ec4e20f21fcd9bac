# SPDX-License-Identifier: Apache-2.0
"""glintinfo: info, validate, diff and export on containers written here directly from
formats/SPEC.md (a second, independent writer: if these files validate, the spec is complete),
on the frozen 1.0 files, and on damaged copies."""

import json
import os
import shutil
import struct

import clitest
from clitest import BAD_ARGS, DIFFERENCES, INVALID, IO, OK, UNSUPPORTED
from containers import (CODEC_ZSTD, SECTION_IMAGE, SECTION_METADATA, SECTION_PRIVATE, build_container, image_payload,
                        metadata, read_sections, zstd_block_frame)

FROZEN_DIR = os.path.join(clitest.SOURCE_DIR, "tests", "format")
SECTION_FLAKES, KIND_NDF_PYRAMID = 80, 1  # formats/SPEC.md 10.5 and section 4


class GlintinfoTest(clitest.ToolTestCase):

    @staticmethod
    def image(offset=0.0):
        values = [0.5 * x + 0.25 * y + layer + offset for layer in range(2) for y in range(4) for x in range(4)]
        return image_payload(4, 4, 1, 2, values)

    def image_container(self, name, offset=0.0, meta=None):
        return self.write(name, build_container([
            (SECTION_METADATA, 0, meta or metadata()),
            (SECTION_IMAGE, 42, self.image(offset)),
            (SECTION_PRIVATE, 7, bytes(range(40))),
        ]))

    @staticmethod
    def read(path):
        with open(path, "rb") as f:
            return f.read()

    def frozen(self, name):
        path = self.path(name)
        shutil.copyfile(os.path.join(FROZEN_DIR, name), path)
        return path

    # --- contract -------------------------------------------------------------------------
    def test_help_and_version(self):
        out, _ = self.run_ok("glintinfo", "--help")
        for command in ("info", "validate", "diff", "export"):
            self.assertIn(command, out)
        out, _ = self.run_ok("glintinfo", "--version")
        self.assertIn("glintinfo", out)
        self.assertIn("container format 1.", out)
        self.assert_fails(BAD_ARGS, "glintinfo")
        self.assert_fails(BAD_ARGS, "glintinfo", "frobnicate")

    # --- info -----------------------------------------------------------------------------
    def test_info_spec_written_file(self):
        path = self.image_container("a.gbk")
        doc = self.run_json("glintinfo", "info", path, schema="glintinfo-info.schema.json")
        self.assertEqual(doc["format_version"], "1.0")
        self.assertEqual(doc["asset_kind"], "test")
        self.assertEqual([s["type_name"] for s in doc["sections"]], ["metadata", "image", "private"])
        self.assertEqual(doc["sections"][1]["key"], 42)
        self.assertEqual(doc["sections"][1]["raw_size"], 32 + 4 * 32)
        self.assertEqual(doc["file_size"], os.path.getsize(path))
        self.assertEqual(doc["metadata"]["generator"]["tool"], "pytest")
        clitest.validate(doc["metadata"], "container-metadata.schema.json")
        out, _ = self.run_ok("glintinfo", "info", path)
        self.assertIn("image", out)
        self.assertIn('"tool": "pytest"', out)

    def test_info_footprint_ranges(self):
        # NDF assets say their map and which footprints each path answers.
        nmap = self.mapgen("beckmann", "b.exr", "--size", "32", "--seed", "3")
        for flakes, lobes in ((True, 16), (True, 0), (False, 16)):
            asset = self.path("a.gbk")
            self.run_ok("ndfgen", nmap, "-o", asset, "--stride", "8", "--sigma0", "4", "--levels", "2", "--ndf-res", "32",
                        "--lobes", str(lobes), "--quiet", *([] if flakes else ["--no-flakes"]))
            doc = self.run_json("glintinfo", "info", asset, schema="glintinfo-info.schema.json")
            self.assertEqual(doc["map"], {"width": 32, "height": 32, "wrap": "repeat"})
            fp = doc["footprints"]
            self.assertEqual((fp["levels"], fp["pyramid_min_sigma"], fp["pyramid_max_sigma"]), (2, 4.0, 8.0))
            self.assertEqual(fp["exact_max_sigma"], 4.0 if flakes else 0.0)
            if flakes and lobes:
                # Flakes to 4, the lobes from 4 sqrt(2) to sqrt(2) sigma0 (the larger), the pyramid from 2 sigma0.
                self.assertAlmostEqual(fp["clustered_min_sigma"], 4.0 * 2 ** 0.5)
                self.assertAlmostEqual(fp["clustered_max_sigma"], 4.0 * 2 ** 0.5)
                self.assertEqual(fp["lobes_per_tile"], 16)
                self.assertEqual(fp["lobes_tile_ratio"], 0.35)  # the default: no probe footprint on this map
                self.assertAlmostEqual(fp["handover_max_sigma"], 8.0)
            else:
                self.assertEqual(fp["clustered_max_sigma"], 0.0)
                self.assertAlmostEqual(fp["handover_max_sigma"], 4.0 * 2 ** 0.5 if flakes else 0.0)
            self.assertTrue(fp["unbounded_above_top"])
            out, _ = self.run_ok("glintinfo", "info", asset)
            self.assertIn("exact from the flakes" if flakes else "no flakes", out)
            if flakes and lobes:
                self.assertIn("clustered lobes (16 per tile, tiles of up to 0.35 sigma)", out)
        # A trailer out of range (a flakes section rebuilt from the spec with a ratio of 5.0, raw
        # blocks in a zstd frame): the JSON leaves the ratio out, the text says so, validate names it.
        sections = read_sections(open(asset, "rb").read())
        sections = [s for s in sections if s[0] != SECTION_FLAKES]
        record = struct.pack("<8I4d", 0x4B4C4647, 3, 32, 32, 0, 1, 0, 16, 0.005, 4.0, 8.0, 4.0 * 2 ** 0.5)
        flakes = record + b"\0" * (32 * 32 * 8) + struct.pack("<2I", 5000, 0)
        sections.append((SECTION_FLAKES, 0, zstd_block_frame(len(flakes), [("raw", flakes)]), CODEC_ZSTD, len(flakes)))
        bad = self.write("bad_trailer.gbk", build_container(sections, kind=KIND_NDF_PYRAMID))
        doc = self.run_json("glintinfo", "info", bad, schema="glintinfo-info.schema.json")
        self.assertNotIn("lobes_tile_ratio", doc["footprints"])
        self.assertEqual(doc["footprints"]["lobes_per_tile"], 16)
        out, _ = self.run_ok("glintinfo", "info", bad)
        self.assertIn("clustered lobes (16 per tile, a tile ratio out of range)", out)
        code, out, _ = clitest.run("glintinfo", "validate", bad, "--json")
        self.assertEqual(code, INVALID)
        self.assertIn(4008, [m["id"] for m in json.loads(out)["messages"]])
        # Containers without levels have neither.
        doc = self.run_json("glintinfo", "info", self.image_container("c.gbk"), schema="glintinfo-info.schema.json")
        self.assertNotIn("footprints", doc)

    def test_info_frozen(self):
        doc = self.run_json("glintinfo", "info", self.frozen("v1_0_image.gbk"), schema="glintinfo-info.schema.json")
        self.assertEqual([s["codec"] for s in doc["sections"]], ["zstd", "zstd", "raw"])
        clitest.validate(doc["metadata"], "container-metadata.schema.json")

    def test_info_errors(self):
        err = self.assert_fails(IO, "glintinfo", "info", self.path("missing.gbk"))
        self.assertIn("missing.gbk", err)
        err = self.assert_fails(INVALID, "glintinfo", "info", self.write("text.gbk", b"hello" * 40))
        self.assertIn("not a glintbake container", err)
        newer = self.write("v2.gbk", build_container([(SECTION_METADATA, 0, metadata())], major=2))
        err = self.assert_fails(UNSUPPORTED, "glintinfo", "info", newer)
        self.assertIn("newer", err)

    # --- validate -------------------------------------------------------------------------
    def test_validate_good_files(self):
        for path in (self.image_container("a.gbk"), self.frozen("v1_0_minimal.gbk"), self.frozen("v1_0_image.gbk")):
            doc = self.run_json("glintinfo", "validate", path, schema="glintinfo-validate.schema.json")
            self.assertTrue(doc["valid"], doc)
            self.assertEqual(doc["messages"], [], doc)
            out, _ = self.run_ok("glintinfo", "validate", path)
            self.assertIn("valid", out)

    def test_validate_corrupted(self):
        data = bytearray(self.read(self.image_container("a.gbk")))
        data[200] ^= 0x10  # inside the image section
        bad = self.write("bad.gbk", bytes(data))
        code, out, err = clitest.run("glintinfo", "validate", bad)
        self.assertEqual(code, INVALID, err)
        self.assertIn("error-4001", out)  # whole-file checksum
        self.assertIn("error-4002", out)  # section checksum
        self.assert_fails(INVALID, "glintinfo", "validate", bad)
        code, out, _ = clitest.run("glintinfo", "validate", bad, "--json")
        self.assertEqual(code, INVALID)
        doc = json.loads(out)
        clitest.validate(doc, "glintinfo-validate.schema.json")
        self.assertFalse(doc["valid"])
        self.assertIn(4002, [m["id"] for m in doc["messages"]])

        header = bytearray(data)
        header[0:128] = self.read(self.path("a.gbk"))[0:128]
        header[40] ^= 1  # index_size, header checksum now wrong
        err = self.assert_fails(INVALID, "glintinfo", "validate", self.write("hdr.gbk", bytes(header)))
        self.assertIn("error-2005", err)

    def test_validate_metadata_and_versions(self):
        leaky = self.write("leak.gbk", build_container([
            (SECTION_METADATA, 0, metadata(asset={"source": "/home/someone/private/map.png"}))]))
        code, out, _ = clitest.run("glintinfo", "validate", leaky)
        self.assertEqual(code, INVALID)
        self.assertIn("error-5014", out)
        none = self.write("nometa.gbk", build_container([(SECTION_PRIVATE, 0, b"abc")]))
        code, out, _ = clitest.run("glintinfo", "validate", none)
        self.assertEqual(code, INVALID)
        self.assertIn("error-5001", out)
        newer_minor = self.write("v1_9.gbk", build_container(
            [(SECTION_METADATA, 0, metadata()), (0x2222, 0, b"future")], minor=9))
        doc = self.run_json("glintinfo", "validate", newer_minor, schema="glintinfo-validate.schema.json")
        self.assertTrue(doc["valid"])
        self.assertEqual(sorted(m["id"] for m in doc["messages"]), [2014, 3011])
        newer_major = self.write("v2.gbk", build_container([(SECTION_METADATA, 0, metadata())], major=2))
        err = self.assert_fails(UNSUPPORTED, "glintinfo", "validate", newer_major)
        self.assertIn("error-2003", err)
        self.assert_fails(IO, "glintinfo", "validate", self.path("missing.gbk"))

    # --- diff -----------------------------------------------------------------------------
    def test_diff(self):
        a = self.image_container("a.gbk")
        b = self.image_container("b.gbk")
        doc = self.run_json("glintinfo", "diff", a, b, schema="glintinfo-diff.schema.json")
        self.assertTrue(doc["same"])
        self.assertEqual([s["comparison"] for s in doc["sections"]], ["metadata", "image", "bytes"])

        # A generator version change alone is not a difference.
        c = self.image_container("c.gbk", meta=metadata(version="9.9"))
        self.run_ok("glintinfo", "diff", a, c)
        d = self.image_container("d.gbk", meta=metadata(tool="other"))
        code, out, _ = clitest.run("glintinfo", "diff", a, d)
        self.assertEqual(code, DIFFERENCES)
        self.assertIn("metadata differs", out)

        shifted = self.image_container("shifted.gbk", offset=1e-3)
        code, out, _ = clitest.run("glintinfo", "diff", a, shifted, "--json")
        self.assertEqual(code, DIFFERENCES)
        doc = json.loads(out)
        clitest.validate(doc, "glintinfo-diff.schema.json")
        self.assertFalse(doc["same"])
        image = doc["sections"][1]
        self.assertEqual(image["status"], "different")
        self.assertAlmostEqual(image["max_abs_diff"], 1e-3, delta=1e-6)
        code, out, _ = clitest.run("glintinfo", "diff", a, shifted)
        self.assertEqual(code, DIFFERENCES)
        self.assertIn("max abs diff", out)
        self.run_ok("glintinfo", "diff", a, shifted, "--abs-tol", "2e-3")
        self.run_ok("glintinfo", "diff", a, shifted, "--rel-tol", "1e-2")

        fewer = self.write("fewer.gbk", build_container([(SECTION_METADATA, 0, metadata())]))
        code, out, _ = clitest.run("glintinfo", "diff", a, fewer, "--json")
        self.assertEqual(code, DIFFERENCES)
        self.assertEqual([s["status"] for s in json.loads(out)["sections"]], ["same", "only-a", "only-a"])
        self.assert_fails(IO, "glintinfo", "diff", a, self.path("missing.gbk"))
        self.assert_fails(BAD_ARGS, "glintinfo", "diff", a, b, "--rel-tol", "-1")

    # --- export ---------------------------------------------------------------------------
    def test_export(self):
        a = self.image_container("a.gbk")
        exr = self.path("layer1.exr")
        doc = self.run_json("glintinfo", "export", a, "image:42", "--layer", "1", "-o", exr,
                            schema="glintinfo-export.schema.json")
        self.assertTrue(os.path.exists(exr))
        self.assertEqual((doc["width"], doc["height"], doc["channels"], doc["scale"]), (4, 4, 1, 1.0))
        png = self.path("layer0.png")
        doc = self.run_json("glintinfo", "export", a, "1", "-o", png, schema="glintinfo-export.schema.json")
        self.assertTrue(os.path.exists(png))
        self.assertAlmostEqual(doc["scale"], 2.25)  # auto: the largest value of layer 0
        self.run_ok("glintinfo", "export", a, "256:42", "--scale", "4", "--channel", "0", "-o", self.path("s.png"))

    def test_export_failures_leave_nothing(self):
        a = self.image_container("a.gbk")
        out = self.path("out.exr")
        self.assert_fails(BAD_ARGS, "glintinfo", "export", a, "1", "--layer", "2", "-o", out, outputs=[out])
        self.assert_fails(BAD_ARGS, "glintinfo", "export", a, "1", "--channel", "1", "-o", out, outputs=[out])
        self.assert_fails(BAD_ARGS, "glintinfo", "export", a, "9", "-o", out, outputs=[out])
        self.assert_fails(BAD_ARGS, "glintinfo", "export", a, "image:43", "-o", out, outputs=[out])
        self.assert_fails(BAD_ARGS, "glintinfo", "export", a, "1", "-o", self.path("out.txt"))
        self.assert_fails(BAD_ARGS, "glintinfo", "export", a, "1", "--scale", "0", "-o", self.path("o.png"))
        self.assert_fails(INVALID, "glintinfo", "export", a, "65536:7", "-o", out, outputs=[out])
        self.assert_fails(IO, "glintinfo", "export", self.path("missing.gbk"), "0", "-o", out, outputs=[out])
        self.assert_fails(IO, "glintinfo", "export", a, "1", "-o", self.path("no-dir/out.exr"))


if __name__ == "__main__":
    clitest.main()
