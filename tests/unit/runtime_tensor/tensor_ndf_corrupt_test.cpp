// SPDX-License-Identifier: Apache-2.0
// TensorNdf on malformed assets: truncated files, bad records, out-of-range index entries, wrong
// section sizes, non-finite factors, plus a mutation loop over the tensor sections. Every case
// must give an error status (or, for harmless mutations, an asset whose queries stay sane), never
// a crash. Containers are rewritten with valid checksums so the runtime's own checks are reached.
#include "tensor_assets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <random>

namespace glintbake::runtime::testing {
namespace {

struct Section {
  uint32_t type;
  uint64_t key;
  std::vector<uint8_t> data;
};

struct Container {
  format::AssetKind kind;
  std::string metadata;
  std::vector<Section> sections;
};

Container decode(const std::vector<uint8_t>& bytes) {
  format::Reader r;
  EXPECT_EQ(r.openMemory(bytes.data(), bytes.size()), format::ContainerStatus::kOk);
  Container c;
  c.kind = r.kind();
  EXPECT_EQ(r.readMetadata(&c.metadata), format::ContainerStatus::kOk);
  for (size_t i = 0; i < r.sections().size(); ++i) {
    const format::SectionInfo& s = r.sections()[i];
    if (s.type == format::kSectionMetadata) continue;
    Section sec{s.type, s.key, {}};
    EXPECT_EQ(r.readSection(i, &sec.data), format::ContainerStatus::kOk);
    c.sections.push_back(std::move(sec));
  }
  return c;
}

std::vector<uint8_t> encode(const Container& c) {
  const std::string path = tempPath("corrupt.gbk");
  format::Writer w;
  EXPECT_EQ(w.open(path, c.kind, 1), format::ContainerStatus::kOk);
  for (const Section& s : c.sections)
    EXPECT_EQ(w.addSection(s.type, s.key, s.data.data(), s.data.size(), format::Codec::kRaw),
              format::ContainerStatus::kOk);
  EXPECT_EQ(w.addMetadata(c.metadata), format::ContainerStatus::kOk);
  EXPECT_EQ(w.finish(), format::ContainerStatus::kOk);
  std::vector<uint8_t> bytes = readFile(path);
  std::remove(path.c_str());
  return bytes;
}

// The section (type, key); a missing one fails the test and yields a scratch section.
Section& sec(Container& c, uint32_t type, uint64_t key) {
  for (Section& s : c.sections)
    if (s.type == type && s.key == key) return s;
  ADD_FAILURE() << "no section " << type << ":" << key;
  static Section scratch{0, 0, {}};
  scratch.data.assign(64, 0);
  return scratch;
}

template <typename T>
void poke(Section& s, size_t offset, T value) {
  ASSERT_LE(offset + sizeof(T), s.data.size());
  std::memcpy(s.data.data() + offset, &value, sizeof(T));
}

RuntimeStatus openBytes(const std::vector<uint8_t>& bytes) {
  TensorNdf t;
  return t.openMemory(bytes.data(), bytes.size());
}

// Applies `mutate` to a decoded copy of the valid asset and opens the result.
RuntimeStatus openMutated(const std::function<void(Container&)>& mutate) {
  Container c = decode(assets().nonneg_bytes);
  mutate(c);
  return openBytes(encode(c));
}

TEST(TensorNdfCorrupt, TheUnmodifiedRoundTripOpens) {
  EXPECT_EQ(openMutated([](Container&) {}), RuntimeStatus::kOk);
}

TEST(TensorNdfCorrupt, TruncatedFiles) {
  const std::vector<uint8_t>& bytes = assets().nonneg_bytes;
  for (size_t n : {size_t(0), size_t(16), size_t(127), bytes.size() / 3, bytes.size() / 2, bytes.size() - 1}) {
    std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + std::ptrdiff_t(n));
    TensorNdf t;
    EXPECT_NE(t.openMemory(cut.empty() ? bytes.data() : cut.data(), n), RuntimeStatus::kOk) << n;
    EXPECT_FALSE(t.isOpen());
  }
}

TEST(TensorNdfCorrupt, BadRecords) {
  using format::kSectionTensorGroup;
  using format::kSectionTensorIndex;
  using format::kSectionTensorInfo;
  const RuntimeStatus bad = RuntimeStatus::kInvalidAsset;
  // Info record.
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorInfo, 0), 0, uint32_t(0x12345678)); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorInfo, 0), 4, uint32_t(2)); }),
            RuntimeStatus::kUnsupportedVersion);
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorInfo, 0), 12, uint32_t(7)); }), bad);  // B
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorInfo, 0), 20, uint32_t(4)); }), bad);  // levels
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorInfo, 0), 24, uint32_t(100000)); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorInfo, 0), 28, uint32_t(65)); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorInfo, 0), 32, uint32_t(2)); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorInfo, 0), 36, uint32_t(4)); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { sec(c, kSectionTensorInfo, 0).data.push_back(0); }), bad);
  // Index entries: group and row out of range; wrong size.
  EXPECT_EQ(openMutated([](Container& c) {
              const uint32_t groups = 1000;
              Section& idx = sec(c, kSectionTensorIndex, 0);
              for (size_t o = 0; o < idx.data.size(); o += 8) poke(idx, o, groups);
            }),
            bad);
  EXPECT_EQ(openMutated([](Container& c) {
              Section& idx = sec(c, kSectionTensorIndex, 0);
              for (size_t o = 0; o < idx.data.size(); o += 8) {
                uint32_t g;
                std::memcpy(&g, idx.data.data() + o, 4);
                if (g != kTensorBlankGroup) {
                  poke(idx, o + 4, uint32_t(1u << 30));
                  return;
                }
              }
            }),
            bad);
  EXPECT_EQ(openMutated([](Container& c) { sec(c, kSectionTensorIndex, 1).data.resize(8); }), bad);
  // Group headers and sizes.
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 0, uint32_t(0)); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 4, uint32_t(8)); }), bad);   // bins
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 8, uint32_t(17)); }), bad);  // rank
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 12, uint32_t(0)); }), bad);  // K
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 16, uint32_t(9)); }), bad);  // level
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 24, uint32_t(1)); }), bad);  // prec.
  EXPECT_EQ(openMutated([](Container& c) { sec(c, kSectionTensorGroup, 0).data.resize(40); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { sec(c, kSectionTensorGroup, 0).data.push_back(0); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { sec(c, kSectionTensorGroup, 0).type = format::kSectionImage; }), bad);
  // Non-finite and negative factors (the asset claims non-negative factors).
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 32, NAN); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 36, -1.0f); }), bad);
  EXPECT_EQ(openMutated([](Container& c) { poke(sec(c, kSectionTensorGroup, 0), 40, 1e30f); }), bad);
  // Missing level record.
  EXPECT_EQ(openMutated([](Container& c) { sec(c, format::kSectionNdfLevel, 2).key = 7; }), bad);
}

TEST(TensorNdfCorrupt, WrongKind) {
  const std::string path = writeReconstructedPyramid(assets().nonneg, "kind");
  TensorNdf t;
  EXPECT_EQ(t.open(path.c_str()), RuntimeStatus::kWrongKind);
  std::remove(path.c_str());
  EXPECT_EQ(t.open(tempPath("does-not-exist.gbk").c_str()), RuntimeStatus::kIoError);
}

TEST(TensorNdfCorrupt, MutationLoopNeverCrashes) {
  const Container valid = decode(assets().signed_bytes);
  std::mt19937_64 rng(2024);
  int rejected = 0, accepted = 0;
  for (int iter = 0; iter < 300; ++iter) {
    Container c = valid;
    // Pick a tensor section; mostly mutate its leading bytes (records and headers).
    std::vector<Section*> targets;
    for (Section& s : c.sections)
      if (s.type == format::kSectionTensorInfo || s.type == format::kSectionTensorIndex ||
          s.type == format::kSectionTensorGroup || s.type == format::kSectionNdfLevel)
        targets.push_back(&s);
    Section& s = *targets[rng() % targets.size()];
    const int edits = 1 + int(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      if (s.data.empty()) break;
      const size_t span = (rng() % 2) ? std::min<size_t>(s.data.size(), 112) : s.data.size();
      const size_t at = size_t(rng() % span);
      switch (rng() % 4) {
        case 0:
          s.data[at] = uint8_t(rng());
          break;
        case 1:
          s.data[at] ^= uint8_t(1u << (rng() % 8));
          break;
        case 2:
          s.data[at] = 0xFF;
          break;
        default:
          s.data.resize(at);
          break;
      }
    }
    const std::vector<uint8_t> bytes = encode(c);
    TensorNdf t;
    if (t.openMemory(bytes.data(), bytes.size()) != RuntimeStatus::kOk) {
      ++rejected;
      continue;
    }
    ++accepted;
    // A mutation the checks accept (e.g. a factor value) must still give sane answers.
    Footprint fp;
    fp.x = 20;
    fp.y = 30;
    fp.sigma = 6;
    double v = -1.0, m = -1.0;
    ASSERT_EQ(t.eval(fp, SPoint{0.01, -0.02}, &v), RuntimeStatus::kOk);
    ASSERT_TRUE(v >= 0.0 && std::isfinite(v));
    ASSERT_EQ(t.mass(fp, &m), RuntimeStatus::kOk);
    ASSERT_TRUE(m >= 0.0 && std::isfinite(m));
    NdfSample smp;
    if (t.sample(fp, 0.3, 0.7, &smp) == RuntimeStatus::kOk) {
      double p = -1.0;
      ASSERT_EQ(t.pdf(fp, smp.s, &p), RuntimeStatus::kOk);
      ASSERT_EQ(p, smp.pdf);
    }
    SRect r;
    ASSERT_EQ(t.average(fp, r, &v), RuntimeStatus::kOk);
    ASSERT_TRUE(v >= 0.0 && std::isfinite(v));
  }
  std::printf("[ figures  ] mutation loop: %d rejected, %d accepted with sane queries\n", rejected, accepted);
  EXPECT_GT(rejected, 100);
}

}  // namespace
}  // namespace glintbake::runtime::testing
