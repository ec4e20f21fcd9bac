// SPDX-License-Identifier: Apache-2.0
// Helpers of the container tests: a scratch directory per test, whole-file reads and writes, and
// a small container built in memory.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace glintbake::format::test {

// A fresh, empty directory removed with its content when the object dies.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  // Names of the entries in the directory, sorted.
  std::vector<std::string> list() const;

 private:
  std::string dir_;
};

std::vector<uint8_t> readFile(const std::string& path);
void writeFile(const std::string& path, const std::vector<uint8_t>& bytes);

// Deterministic pseudo-random bytes (xorshift), incompressible.
std::vector<uint8_t> noiseBytes(size_t size, uint64_t seed);
// Compressible bytes: a repeating ramp.
std::vector<uint8_t> rampBytes(size_t size);

// A valid metadata JSON text for AssetKind::kTest.
std::string testMetadata();

// Writes a small container (metadata, one zstd section, one raw section, one empty section) to
// path and returns its bytes.
std::vector<uint8_t> makeSmallContainer(const std::string& path);

// Recomputes the header checksum in place (after a test edits header fields on purpose).
void resealHeader(std::vector<uint8_t>* bytes);
// Recomputes the index checksum, then the header checksum (after editing index entries).
void resealIndex(std::vector<uint8_t>* bytes);
// Recomputes the file checksum, then the header checksum.
void resealFile(std::vector<uint8_t>* bytes);

}  // namespace glintbake::format::test
