// Writes v1_0_minimal.gbk and v1_0_image.gbk. Run ONCE, when a format version is introduced;
// never to "update" existing files (see README.md). Not part of the build:
//   c++ -std=c++17 -I formats/include generate_frozen.cpp -L<build>/formats -lglintbake_format ...
#include "frozen_content.h"

#include <cstdio>

int main() {
  using namespace glintbake::format;
  {
    Writer writer;
    if (writer.open("v1_0_minimal.gbk", AssetKind::kTest) != Status::kOk) return 1;
    if (writer.addMetadata(frozen::minimalMetadata()) != Status::kOk) return 1;
    if (writer.finish() != Status::kOk) return 1;
  }
  {
    Writer writer;
    if (writer.open("v1_0_image.gbk", AssetKind::kTest, 9) != Status::kOk) return 1;
    if (writer.addMetadata(frozen::imageMetadata()) != Status::kOk) return 1;
    const auto image = frozen::imageSection();
    if (writer.addSection(kSectionImage, frozen::kImageKey, image.data(), image.size(), Codec::kZstd) != Status::kOk)
      return 1;
    const auto raw = frozen::privateSection();
    if (writer.addSection(kSectionFirstPrivate, frozen::kPrivateKey, raw.data(), raw.size(), Codec::kRaw) !=
        Status::kOk)
      return 1;
    if (writer.finish() != Status::kOk) return 1;
  }
  std::puts("wrote v1_0_minimal.gbk and v1_0_image.gbk");
  return 0;
}
