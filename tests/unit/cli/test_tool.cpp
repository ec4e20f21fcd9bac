// SPDX-License-Identifier: Apache-2.0
// Tests of the shared command scaffolding: exit codes, atomic outputs, depfiles, metadata.
#include <glintbake/cli/tool.h>

#include "../file_size_limit.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;
using namespace glintbake::cli;

namespace {

fs::path scratchDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("glintbake-cli-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int runWith(std::vector<std::string> args, const std::function<int(Tool&)>& body) {
  Tool tool("testtool", "A test tool");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return tool.run(int(argv.size()), argv.data(), body);
}

}  // namespace

TEST(Tool, ExitCodesFollowErrors) {
  EXPECT_EQ(runWith({"testtool"}, [](Tool&) { return kExitOk; }), kExitOk);
  EXPECT_EQ(runWith({"testtool"}, [](Tool&) -> int { throw Error(kExitInvalidInput, "bad"); }), kExitInvalidInput);
  EXPECT_EQ(runWith({"testtool"}, [](Tool&) -> int { throw std::bad_alloc(); }), kExitRuntime);
  EXPECT_EQ(runWith({"testtool", "--no-such-option"}, [](Tool&) { return kExitOk; }), kExitBadArguments);
  EXPECT_EQ(runWith({"testtool", "--threads", "-3"}, [](Tool&) { return kExitOk; }), kExitBadArguments);
  EXPECT_EQ(runWith({"testtool", "--version"}, [](Tool&) { return kExitRuntime; }), kExitOk);
}

TEST(Tool, ThreadsOptionIsApplied) {
  int seen = 0;
  EXPECT_EQ(runWith({"testtool", "-j", "3"},
                    [&](Tool& t) {
                      seen = t.threadCount();
                      return 0;
                    }),
            0);
  EXPECT_EQ(seen, 3);
  EXPECT_EQ(runWith({"testtool"},
                    [&](Tool& t) {
                      seen = t.threadCount();
                      return 0;
                    }),
            0);
  EXPECT_GE(seen, 1);
}

TEST(AtomicOutput, LeavesNothingUnlessCommitted) {
  const fs::path dir = scratchDir("atomic");
  const fs::path target = dir / "out.bin";
  {
    AtomicOutput out(target.string());
    out.write("partial");
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 0);
  {
    AtomicOutput out(target.string());
    out.write("complete");
    out.commit();
  }
  EXPECT_EQ(readText(target), "complete");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

TEST(AtomicOutput, MissingDirectoryFailsWithIoCode) {
  try {
    AtomicOutput out("/nonexistent-dir-for-glintbake/out.bin");
    out.commit();
    FAIL() << "opening should fail";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), kExitIo);
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
  }
}

TEST(AtomicOutput, FileSizeLimitFailsWithIoCode) {
  const fs::path dir = scratchDir("atomic-limit");
  try {
    glintbake::test::FileSizeLimit limit(1024);
    writeOutputFile((dir / "big.bin").string(), std::string(64 * 1024, 'x'));
    FAIL() << "the write should fail";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), kExitIo);
    EXPECT_NE(std::string(e.what()).find("File too large"), std::string::npos) << e.what();
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 0);
  fs::remove_all(dir);
}

TEST(Depfile, MakeSyntaxWithEscapes) {
  const fs::path dir = scratchDir("depfile");
  const fs::path dep = dir / "x.d";
  writeDepfile(dep.string(), {"out/a b.gbk"}, {"in/map.png", "in/$weird.png"});
  EXPECT_EQ(readText(dep), "out/a\\ b.gbk: \\\n  in/map.png \\\n  in/$$weird.png\n");
  fs::remove_all(dir);
}

TEST(Metadata, RecordsNamesAndHashesNeverPaths) {
  const fs::path dir = scratchDir("meta");
  const fs::path input = dir / "map.bin";
  std::ofstream(input) << "some bytes";
  Tool tool("testtool", "A test tool");
  const std::string hash = tool.addInput(input.string());
  EXPECT_EQ(hash.rfind("xxh3-128:", 0), 0u);
  EXPECT_EQ(hash.size(), 9u + 32u);
  const Json meta = tool.makeMetadata("test", Json{{"rank", 16}});
  EXPECT_EQ(meta["inputs"][0]["name"], "map.bin");
  EXPECT_EQ(meta["inputs"][0]["hash"], hash);
  EXPECT_EQ(meta["parameters"]["rank"], 16);
  EXPECT_EQ(meta.dump().find(dir.string()), std::string::npos);
  EXPECT_THROW(tool.addInput((dir / "missing.bin").string()), Error);
  fs::remove_all(dir);
}

TEST(Names, BaseName) {
  EXPECT_EQ(baseName("/a/b/c.png"), "c.png");
  EXPECT_EQ(baseName("c.png"), "c.png");
  EXPECT_EQ(baseName("a\\b.png"), "b.png");
}
