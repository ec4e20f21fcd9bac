// SPDX-License-Identifier: Apache-2.0
// A renderer-side consumer of an installed glintbake (COMPONENTS runtime): writes a container,
// reads it back through the installed format library, and asks the runtime about it.
#include <glintbake/format/container.h>
#include <glintbake/runtime/ndf_asset.h>
#include <glintbake/runtime/runtime.h>
#include <glintbake/runtime/version.h>
#include <glintbake/version.h>

#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) return 1;
  namespace fmt = glintbake::format;
  const std::string meta = R"({"schema":"glintbake.container-metadata/1","asset_kind":"test",)"
                           R"("generator":{"tool":"consumer","version":"0"},"parameters":{},"inputs":[]})";
  const std::vector<float> payload(1000, 0.5f);
  fmt::Writer writer;
  if (writer.open(argv[1], fmt::AssetKind::kTest) != fmt::ContainerStatus::kOk) return 2;
  if (writer.addMetadata(meta) != fmt::ContainerStatus::kOk) return 2;
  if (writer.addSection(fmt::kSectionFirstPrivate, 7, payload.data(), payload.size() * sizeof(float)) !=
      fmt::ContainerStatus::kOk)
    return 2;
  if (writer.finish() != fmt::ContainerStatus::kOk) return 2;

  fmt::Reader reader;
  if (reader.open(argv[1]) != fmt::ContainerStatus::kOk) return 3;
  const int index = reader.find(fmt::kSectionFirstPrivate, 7);
  std::vector<uint8_t> bytes;
  if (index < 0 || reader.readSection(size_t(index), &bytes) != fmt::ContainerStatus::kOk) return 3;
  if (bytes.size() != payload.size() * sizeof(float)) return 3;
  // The library linked is the one the headers describe.
  if (std::string(glintbake::runtime::versionString()) != GLINTBAKE_VERSION_STRING) return 4;
  // A test container is no NDF asset: the open fails and says why.
  glintbake::runtime::NdfAsset asset;
  glintbake::runtime::OpenError error;
  if (asset.open(argv[1], &error) != glintbake::runtime::RuntimeStatus::kWrongKind || error.message[0] == '\0') return 5;
  std::printf("consumer ok: %s, runtime says '%s'\n", fmt::assetKindString(reader.kind()),
              glintbake::runtime::statusString(glintbake::runtime::RuntimeStatus::kOk));
  return 0;
}
