// SPDX-License-Identifier: Apache-2.0
// The shared ingest options: parsing, range checks (bad values are argument errors, exit 1),
// canonical JSON, and the loader's mapping of library errors to exit codes.
#include <glintbake/bake/io/image_io.h>
#include <glintbake/cli/ingest_options.h>

#include "test_support.h"

#include <string>
#include <vector>

namespace glintbake::cli {
namespace {

bool parse(std::vector<std::string> args, bake::IngestOptions* options) {
  CLI::App app("test");
  addIngestOptions(app, *options);
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses a reversed vector
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError&) {
    return false;
  }
  return true;
}

TEST(IngestOptions, ParsesEveryOption) {
  bake::IngestOptions o;
  ASSERT_TRUE(parse({"--encoding", "snorm", "--flip-green", "--height", "--height-scale", "2.5", "--wrap", "clamp",
                     "--part", "1", "--fix-nonfinite", "--max-size", "64"},
                    &o));
  EXPECT_EQ(o.encoding, bake::Encoding::kSnorm);
  EXPECT_TRUE(o.flip_green);
  EXPECT_TRUE(o.height);
  EXPECT_EQ(o.height_scale, 2.5);
  EXPECT_EQ(o.wrap, bake::Wrap::kClamp);
  EXPECT_EQ(o.part, 1);
  EXPECT_TRUE(o.fix_nonfinite);
  EXPECT_EQ(o.max_size, 64);

  bake::IngestOptions d;
  ASSERT_TRUE(parse({}, &d));
  EXPECT_EQ(d.encoding, bake::Encoding::kAuto);
  EXPECT_EQ(d.wrap, bake::Wrap::kRepeat);
}

TEST(IngestOptions, RejectsBadValues) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{{"--encoding", "srgb"},
                                                                                    {"--wrap", "mirror"},
                                                                                    {"--height-scale", "0"},
                                                                                    {"--height-scale", "-1"},
                                                                                    {"--part", "-1"},
                                                                                    {"--max-size", "0"},
                                                                                    {"--max-size", "2000000"}}) {
    bake::IngestOptions o;
    EXPECT_FALSE(parse(args, &o)) << args[0] << " " << args[1];
  }
}

TEST(IngestOptions, CanonicalJson) {
  bake::IngestOptions o;
  o.encoding = bake::Encoding::kUnorm;
  o.wrap = bake::Wrap::kClamp;
  const Json j = ingestOptionsJson(o);
  EXPECT_EQ(j["encoding"], "unorm");
  EXPECT_EQ(j["wrap"], "clamp");
  EXPECT_EQ(j["flip_green"], false);
  EXPECT_EQ(j.dump(), ingestOptionsJson(o).dump());

  bake::IngestReport r;
  r.texels = 16;
  r.far_from_unit = 2;
  r.content_hash = "xxh3-128:00";
  const Json rj = ingestReportJson(r);
  EXPECT_EQ(rj["texels"], 16);
  EXPECT_EQ(rj["far_from_unit"], 2);
  EXPECT_EQ(rj["hash"], "xxh3-128:00");
}

TEST(IngestOptions, LoaderMapsErrorsToExitCodes) {
  test::ScratchDir dir;
  Tool tool("testtool", "test");
  bake::IngestOptions options;
  try {
    loadNormalMapForTool(tool, dir.file("missing.png"), options, nullptr);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), kExitIo);
  }
  const std::string garbage = dir.file("garbage.exr");
  test::writeBytes(garbage, "this is not an image at all");
  try {
    loadNormalMapForTool(tool, garbage, options, nullptr);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), kExitInvalidInput);
    EXPECT_NE(std::string(e.what()).find("garbage.exr"), std::string::npos);
  }
  bake::NormalMap flat;
  flat.width = flat.height = 4;
  flat.normals.assign(4 * 4 * 3, 0.0f);
  for (size_t i = 2; i < flat.normals.size(); i += 3) flat.normals[i] = 1.0f;
  const std::string good = dir.file("flat.exr");
  ASSERT_TRUE(bake::writeNormalMap(good, flat).ok());
  bake::IngestReport report;
  const bake::NormalMap map = loadNormalMapForTool(tool, good, options, &report);
  EXPECT_EQ(map.width, 4);
  EXPECT_EQ(report.texels, 16);
  ASSERT_FALSE(tool.inputs().empty());
  EXPECT_EQ(tool.inputs().back(), good);
}

}  // namespace
}  // namespace glintbake::cli
