// SPDX-License-Identifier: Apache-2.0
// The kind and section-type registry (kinds.h): names, ranges and the rules derived from it, and
// its agreement with the tables of formats/SPEC.md sections 3 and 4.
#include <glintbake/format/container.h>
#include <glintbake/format/kinds.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

namespace glintbake::format {
namespace {

std::string specText() {
  std::ifstream in(std::string(GLINTBAKE_TEST_DATA_DIR) + "/../../../formats/SPEC.md");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string number(uint32_t v) {
  if (v < 0x1000) return std::to_string(v);
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%X", v);
  return buf;
}

// The text between a heading and the next heading of the same or a higher level.
std::string specSection(const std::string& spec, const std::string& heading) {
  const size_t start = spec.find("\n" + heading);
  if (start == std::string::npos) return "";
  const size_t end = spec.find("\n## ", start + 1);
  return spec.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

TEST(KindRegistry, NamesRoundTrip) {
  for (const KindInfo& k : kKindRegistry) {
    EXPECT_STREQ(assetKindString(k.kind), k.name);
    AssetKind parsed = AssetKind::kUnknown;
    EXPECT_TRUE(assetKindFromString(k.name, &parsed));
    EXPECT_EQ(parsed, k.kind);
  }
  for (const SectionTypeInfo& t : kSectionTypeRegistry) {
    EXPECT_STREQ(sectionTypeString(t.type), t.name);
    EXPECT_TRUE(isRegisteredSectionType(t.type));
  }
  EXPECT_STREQ(assetKindString(AssetKind::kUnknown), "unknown");
}

TEST(KindRegistry, RangesAreDisjointAndOwned) {
  for (size_t i = 0; i < std::size(kSectionRanges); ++i) {
    EXPECT_LE(kSectionRanges[i].first, kSectionRanges[i].last);
    if (i > 0) {
      EXPECT_GT(kSectionRanges[i].first, kSectionRanges[i - 1].last);
    }
  }
  for (const KindInfo& k : kKindRegistry) {
    if (k.last_type == 0) continue;
    const SectionRange* r = findSectionRange(k.first_type);
    ASSERT_NE(r, nullptr) << k.name;
    EXPECT_STREQ(r->owner, k.name);
    EXPECT_EQ(r->first, k.first_type);
    EXPECT_EQ(r->last, k.last_type);
  }
  for (const SectionTypeInfo& t : kSectionTypeRegistry) EXPECT_NE(findSectionRange(t.type), nullptr) << t.name;
  // The new kinds and the flakes family have blocks of their own (the flakes family defines 80).
  for (const char* owner : {"flakes", "wang-tiles", "tiny-example", "glitter"}) {
    bool found = false;
    for (const SectionRange& r : kSectionRanges) found = found || std::string(r.owner) == owner;
    EXPECT_TRUE(found) << owner;
  }
  EXPECT_TRUE(isRegisteredSectionType(kSectionFlakes));
  EXPECT_FALSE(isRegisteredSectionType(81));  // flakes: reserved, not defined
  EXPECT_TRUE(isRegisteredSectionType(40));   // tensor-ndf's open block
  EXPECT_TRUE(isRegisteredSectionType(kSectionFirstPrivate + 5));
}

TEST(KindRegistry, SpecTablesAgree) {
  const std::string spec = specText();
  ASSERT_FALSE(spec.empty());
  const std::string kinds = specSection(spec, "## 4. Asset kinds");
  for (const KindInfo& k : kKindRegistry) {
    const std::string row = "| " + number(uint32_t(k.kind)) + " | " + k.name + " |";
    const size_t at = kinds.find(row);
    ASSERT_NE(at, std::string::npos) << row;
    const std::string line = kinds.substr(at, kinds.find('\n', at) - at);
    if (k.last_type != 0) {
      EXPECT_NE(line.find(" " + std::to_string(k.first_type) + "-" + std::to_string(k.last_type)), std::string::npos)
          << line;
    }
    if (k.tool[0] != '\0') {
      EXPECT_NE(line.find(std::string("| ") + k.tool + " |"), std::string::npos) << line;
    }
  }
  const std::string types = specSection(spec, "## 3. Section types");
  for (const SectionRange& r : kSectionRanges) {
    const std::string row = "| " + std::to_string(r.first) + "-" + std::to_string(r.last) + " | " + r.owner;
    EXPECT_NE(types.find(row), std::string::npos) << row;
  }
  for (const SectionTypeInfo& t : kSectionTypeRegistry) {
    const std::string row = "| " + std::to_string(t.type) + " | " + t.name + " |";
    EXPECT_NE(types.find(row), std::string::npos) << row;
  }
}

}  // namespace
}  // namespace glintbake::format
