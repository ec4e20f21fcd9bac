// SPDX-License-Identifier: Apache-2.0
// AtomicFile: nothing at the path before commit(), nothing left on failure, a failed write under a
// file-size limit is an error (EFBIG) and keeps the previous file.
#include <glintbake/format/atomic_file.h>
#include <glintbake/format/container.h>

#include "../file_size_limit.h"
#include "test_files.h"

#include <gtest/gtest.h>

#include <cerrno>
#include <string>
#include <vector>

namespace glintbake::format {
namespace {

using test::ScratchDir;

using glintbake::test::FileSizeLimit;

TEST(AtomicFile, AppearsOnlyOnCommit) {
  ScratchDir dir;
  const std::string path = dir.path("out.bin");
  AtomicFile file;
  ASSERT_EQ(file.open(path), ContainerStatus::kOk);
  ASSERT_EQ(file.write("hello", 5), ContainerStatus::kOk);
  ASSERT_EQ(file.writeAt("J", 1, 0), ContainerStatus::kOk);
  // Anonymous, or one named temporary file beside the destination.
  const std::vector<std::string> during = dir.list();
  if (file.temporaryPath().empty()) {
    EXPECT_TRUE(during.empty());
  } else {
    ASSERT_EQ(during.size(), 1u);
    EXPECT_EQ(during[0].rfind("out.bin.tmp-", 0), 0u);
  }
  ASSERT_EQ(file.commit(), ContainerStatus::kOk);
  EXPECT_EQ(dir.list(), std::vector<std::string>{"out.bin"});
  const std::vector<uint8_t> bytes = test::readFile(path);
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()), "Jello");
}

TEST(AtomicFile, ReplacesAnExistingFile) {
  ScratchDir dir;
  const std::string path = dir.path("out.bin");
  ASSERT_EQ(writeFileAtomically(path, "first", 5), ContainerStatus::kOk);
  ASSERT_EQ(writeFileAtomically(path, "second", 6), ContainerStatus::kOk);
  EXPECT_EQ(dir.list(), std::vector<std::string>{"out.bin"});
  const std::vector<uint8_t> bytes = test::readFile(path);
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()), "second");
}

TEST(AtomicFile, AbortAndDestructionLeaveNothing) {
  ScratchDir dir;
  {
    AtomicFile file;
    ASSERT_EQ(file.open(dir.path("a.bin")), ContainerStatus::kOk);
    ASSERT_EQ(file.write("x", 1), ContainerStatus::kOk);
  }
  AtomicFile file;
  ASSERT_EQ(file.open(dir.path("b.bin")), ContainerStatus::kOk);
  file.abort();
  EXPECT_TRUE(dir.list().empty());
  AtomicFile nowhere;
  EXPECT_EQ(nowhere.open(dir.path("missing-dir/x.bin")), ContainerStatus::kIoError);
  EXPECT_EQ(nowhere.errorNumber(), ENOENT);
}

TEST(AtomicFile, FileSizeLimitIsAnErrorAndKeepsThePreviousFile) {
  ScratchDir dir;
  const std::string path = dir.path("out.bin");
  ASSERT_EQ(writeFileAtomically(path, "previous", 8), ContainerStatus::kOk);
  const std::vector<uint8_t> big = test::noiseBytes(64 * 1024, 1);
  std::string message;
  {
    FileSizeLimit limit(4096);
    EXPECT_EQ(writeFileAtomically(path, big.data(), big.size(), &message), ContainerStatus::kIoError);
  }
  EXPECT_NE(message.find("File too large"), std::string::npos) << message;
  EXPECT_EQ(dir.list(), std::vector<std::string>{"out.bin"});
  const std::vector<uint8_t> bytes = test::readFile(path);
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()), "previous");
}

TEST(AtomicFile, ContainerWriterReportsTheFileSizeLimit) {
  ScratchDir dir;
  const std::string path = dir.path("c.gbk");
  const std::vector<uint8_t> big = test::noiseBytes(256 * 1024, 2);
  FileSizeLimit limit(16 * 1024);
  Writer writer;
  ASSERT_EQ(writer.open(path, AssetKind::kTest), ContainerStatus::kOk);
  EXPECT_EQ(writer.addSection(kSectionImage, 0, big.data(), big.size()), ContainerStatus::kIoError);
  EXPECT_EQ(writer.errorNumber(), EFBIG);
  EXPECT_EQ(writer.errorString(ContainerStatus::kIoError), "File too large");
  EXPECT_NE(writer.finish(), ContainerStatus::kOk);
  EXPECT_TRUE(dir.list().empty());
}

}  // namespace
}  // namespace glintbake::format
