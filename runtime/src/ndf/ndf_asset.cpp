// SPDX-License-Identifier: Apache-2.0
// NdfAsset: an opened NDF asset with its container metadata, and open failures explained by the
// container validator (the same checks and message ids as `glintinfo validate`).
#include <glintbake/format/container.h>
#include <glintbake/format/validate.h>
#include <glintbake/runtime/ndf_asset.h>
#include <glintbake/runtime/version.h>

#include <cstdio>
#include <cstring>
#include <new>
#include <string>

namespace glintbake::runtime {
namespace {

void setMessage(OpenError* error, int32_t id, const char* text) {
  error->message_id = id;
  std::snprintf(error->message, sizeof(error->message), "%s", text);
}

// Fills *error for a failed open: the validator's first error when it finds one, otherwise the
// runtime's own reason. `validateAgain` runs the validator on the same bytes; `kindOf` reads the
// container's kind (for kWrongKind).
template <typename Validate, typename KindOf>
void explain(RuntimeStatus status, OpenError* error, Validate validateAgain, KindOf kindOf) {
  if (!error) return;
  error->status = status;
  if (status == RuntimeStatus::kInvalidArgument) {
    setMessage(error, 0, "no asset given (null path or buffer)");
    return;
  }
  if (status == RuntimeStatus::kOutOfMemory) {
    setMessage(error, 0, "out of memory while loading the asset");
    return;
  }
  const format::ValidationReport report = validateAgain();
  for (const format::ValidationMessage& m : report.messages) {
    if (m.severity != format::Severity::kError) continue;
    setMessage(error, m.id, m.message.c_str());
    return;
  }
  if (status == RuntimeStatus::kWrongKind) {
    char text[OpenError::kMessageCapacity];
    std::snprintf(text, sizeof(text), "the container holds a '%s' asset, not an NDF asset (ndf-pyramid, tensor-ndf, glitter)",
                  format::assetKindString(kindOf()));
    setMessage(error, 0, text);
    return;
  }
  char text[OpenError::kMessageCapacity];
  std::snprintf(text, sizeof(text), "%s: the container is sound but its %s content was refused by the runtime",
                statusString(status), format::assetKindString(kindOf()));
  setMessage(error, 0, text);
}

void clear(OpenError* error) {
  if (!error) return;
  error->status = RuntimeStatus::kOk;
  error->message_id = 0;
  error->message[0] = '\0';
}

// Copies the metadata text of an opened container (absent or unreadable metadata: empty; the
// validator is the place that reports it).
RuntimeStatus copyMetadata(const format::Reader& reader, std::unique_ptr<char[]>* out, size_t* size) {
  std::string json;
  if (reader.readMetadata(&json) != format::ContainerStatus::kOk) json.clear();
  std::unique_ptr<char[]> text(new (std::nothrow) char[json.size() + 1]);
  if (!text) return RuntimeStatus::kOutOfMemory;
  std::memcpy(text.get(), json.data(), json.size());
  text[json.size()] = '\0';
  *out = std::move(text);
  *size = json.size();
  return RuntimeStatus::kOk;
}

format::AssetKind kindOfFile(const char* path) {
  format::Reader reader;
  return reader.open(path) == format::ContainerStatus::kOk ? reader.kind() : format::AssetKind::kUnknown;
}
format::AssetKind kindOfMemory(const void* data, size_t size) {
  format::Reader reader;
  return reader.openMemory(data, size) == format::ContainerStatus::kOk ? reader.kind() : format::AssetKind::kUnknown;
}

}  // namespace

Version version() {
  Version v;
  v.major = GLINTBAKE_VERSION_MAJOR;
  v.minor = GLINTBAKE_VERSION_MINOR;
  v.patch = GLINTBAKE_VERSION_PATCH;
  return v;
}

const char* versionString() { return GLINTBAKE_VERSION_STRING; }

RuntimeStatus openNdfAsset(const char* path, std::unique_ptr<NdfSource>* out, OpenError* error) {
  clear(error);
  const RuntimeStatus s = openNdfAsset(path, out);
  if (s != RuntimeStatus::kOk && path)
    explain(s, error, [&] { return format::validateFile(path); }, [&] { return kindOfFile(path); });
  else if (s != RuntimeStatus::kOk)
    explain(s, error, [] { return format::ValidationReport(); }, [] { return format::AssetKind::kUnknown; });
  return s;
}

RuntimeStatus openNdfAssetMemory(const void* data, size_t size, std::unique_ptr<NdfSource>* out, OpenError* error) {
  clear(error);
  const RuntimeStatus s = openNdfAssetMemory(data, size, out);
  if (s != RuntimeStatus::kOk && data)
    explain(s, error, [&] { return format::validate(data, size); }, [&] { return kindOfMemory(data, size); });
  else if (s != RuntimeStatus::kOk)
    explain(s, error, [] { return format::ValidationReport(); }, [] { return format::AssetKind::kUnknown; });
  return s;
}

NdfAsset::NdfAsset() = default;
NdfAsset::~NdfAsset() = default;

void NdfAsset::close() {
  source_.reset();
  metadata_.reset();
  metadata_size_ = 0;
  kind_ = format::AssetKind::kUnknown;
}

const char* NdfAsset::kindName() const { return format::assetKindString(kind_); }

// Keeps an opened source with the metadata and kind of its container.
RuntimeStatus NdfAsset::adopt(const format::Reader& reader, std::unique_ptr<NdfSource> source, OpenError* error) {
  if (RuntimeStatus m = copyMetadata(reader, &metadata_, &metadata_size_); m != RuntimeStatus::kOk) {
    explain(m, error, [] { return format::ValidationReport(); }, [] { return format::AssetKind::kUnknown; });
    return m;
  }
  kind_ = source->kind();
  source_ = std::move(source);
  return RuntimeStatus::kOk;
}

RuntimeStatus NdfAsset::open(const char* path, OpenError* error) {
  close();
  std::unique_ptr<NdfSource> source;
  const RuntimeStatus s = openNdfAsset(path, &source, error);
  if (s != RuntimeStatus::kOk) return s;
  format::Reader reader;
  if (reader.open(path) != format::ContainerStatus::kOk) {
    // The file changed between the two reads.
    if (error) {
      error->status = RuntimeStatus::kIoError;
      setMessage(error, 0, "the asset could not be read again for its metadata");
    }
    return RuntimeStatus::kIoError;
  }
  return adopt(reader, std::move(source), error);
}

RuntimeStatus NdfAsset::openMemory(const void* data, size_t size, OpenError* error) {
  close();
  std::unique_ptr<NdfSource> source;
  const RuntimeStatus s = openNdfAssetMemory(data, size, &source, error);
  if (s != RuntimeStatus::kOk) return s;
  format::Reader reader;
  if (reader.openMemory(data, size) != format::ContainerStatus::kOk) return RuntimeStatus::kInvalidAsset;
  return adopt(reader, std::move(source), error);
}

}  // namespace glintbake::runtime
