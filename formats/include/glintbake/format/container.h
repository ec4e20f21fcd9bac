// SPDX-License-Identifier: Apache-2.0
// glintbake container: reading and writing versioned, sectioned asset files (.gbk).
//
// The byte layout is normative in formats/SPEC.md. This header is the whole public API of the
// container library (target glintbake::format). It depends on zstd and xxhash only, throws no
// exceptions and reports every failure through a ContainerStatus code.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace glintbake::format {

// Container format version written by this library. A reader accepts any minor version of its
// major version (unknown sections are skipped); a newer major version is refused.
constexpr uint16_t kFormatVersionMajor = 1;
constexpr uint16_t kFormatVersionMinor = 0;

// Fixed sizes and limits of the layout (see SPEC.md).
constexpr size_t kHeaderSize = 128;                                // bytes of the file header
constexpr size_t kIndexEntrySize = 64;                             // bytes of one section index entry
constexpr size_t kSectionAlignment = 64;                           // every section and the index start at a multiple
constexpr uint64_t kDefaultMaxRawSectionSize = uint64_t(1) << 32;  // 4 GiB: readers' default cap
constexpr uint32_t kMaxSectionCount = 1u << 24;                    // readers refuse more
constexpr uint64_t kMaxMetadataSize = uint64_t(16) << 20;          // 16 MiB: metadata text limit
constexpr uint64_t kMaxZstdWindowSize = uint64_t(1) << 27;         // 128 MiB: largest zstd window read
constexpr int kMaxJsonDepth = 64;                                  // nesting limit of every JSON input

enum class ContainerStatus : int32_t {
  kOk = 0,
  kIoError = 1,             // open/read/write/rename failed
  kBadMagic = 2,            // not a glintbake container
  kUnsupportedVersion = 3,  // newer major version than this reader
  kCorruptHeader = 4,       // header fields out of range or header checksum mismatch
  kCorruptIndex = 5,        // index entries out of range, overlapping, misaligned, or checksum mismatch
  kChecksumMismatch = 6,    // a section's stored bytes or the whole file fail their checksum
  kDecompressFailed = 7,    // zstd refused the section or it did not decode to its raw size
  kTooLarge = 8,            // a size exceeds a reader limit (raw size cap, section count cap, zstd window)
  kNotFound = 9,            // no section with that type/key
  kInvalidArgument = 10,    // caller error (bad codec, writer already finished, ...)
  kTruncated = 11,          // the file is shorter than its header or index says
};

// The former name of ContainerStatus, kept for one minor version.
using Status [[deprecated("use glintbake::format::ContainerStatus")]] = ContainerStatus;

// Stable, human-readable name of a status ("ok", "i/o error", ...). Never returns null.
const char* statusString(ContainerStatus status);

// What an asset file holds. Stored as uint32; unknown values are readable (kind is reported as a number).
enum class AssetKind : uint32_t {
  kUnknown = 0,
  kNdfPyramid = 1,   // ndfgen: NDF images on the footprint pyramid
  kTensorNdf = 2,    // tensorpack: CP-compressed NDF blocks
  kLtcTable = 3,     // ltcfit table
  kRoughness = 4,    // ltcfit roughness mips
  kWangTiles = 5,    // wangtile
  kTinyExample = 6,  // tinyexample
  kGlitter = 7,      // procedural discrete microfacets
  kPartial = 8,      // one shard of a sharded bake (glintinfo merge); never an asset (SPEC.md 10.9)
  kTest = 0x7fff,    // containers made by tests and fuzzers
};
// True when data (size bytes, >= 8 needed) starts with the container's 8-byte magic: a cheap test
// of whether a file is a glintbake container before choosing how to read it.
bool hasContainerMagic(const void* data, size_t size);

const char* assetKindString(AssetKind kind);  // "ndf-pyramid", "tensor-ndf", ...; "unknown" otherwise
bool assetKindFromString(const std::string& name, AssetKind* kind);

enum class Codec : uint32_t {
  kRaw = 0,   // stored bytes are the raw bytes
  kZstd = 1,  // one zstd frame whose content size equals raw_size
};
const char* codecString(Codec codec);

// Section types. 0-0xFFFF are reserved for this specification (SPEC.md lists them); readers skip
// types they do not know. The 64-bit key distinguishes sections of the same type (e.g. level and
// region of an NDF chunk); its meaning is defined per type in SPEC.md.
enum SectionType : uint32_t {
  kSectionMetadata = 1,            // UTF-8 JSON object, schemas/container-metadata.schema.json. Exactly one.
  kSectionNdfLevel = 16,           // ndf-pyramid: per-level descriptor (key = level)
  kSectionNdfChunk = 17,           // ndf-pyramid: NDF images of one spatial region (key = level << 32 | region)
  kSectionTensorIndex = 32,        // tensor-ndf: (level, centre, block) -> (group, row) (key = level)
  kSectionTensorInfo = 33,         // tensor-ndf: asset descriptor (key = 0)
  kSectionTensorGroup = 34,        // tensor-ndf: CP factors of one group (key = group id)
  kSectionLtcTable = 48,           // ltc-table sections (48-63)
  kSectionRoughness = 64,          // roughness mips (64-79)
  kSectionFlakes = 80,             // NDF assets: the source normal map for exact small footprints (key = 0)
  kSectionWangInfo = 96,           // wang-tiles: the tile-set record (key = 0)
  kSectionWangEdges = 97,          // wang-tiles: edge colours of every tile and the edge-code-to-tile map (key = 0)
  kSectionWangTexels = 98,         // wang-tiles: (n_x, n_y) of every texel of every tile (key = 0)
  kSectionWangTileNdf = 99,        // wang-tiles: one tile's NDF asset, an embedded container (key = tile)
  kSectionGlitterInfo = 128,       // glitter: the surface record (key = 0)
  kSectionGlitterIntegrals = 129,  // glitter: the cached triangle integrals of the smooth NDF (key = 0)
  kSectionShardMetadata = 144,     // partial: the metadata text of the merged asset (key = 0)
  kSectionShardSection = 145,      // partial: one section of the merged asset (key = its position)
  kSectionImage = 0x100,           // generic float image (key = user-defined), see ImageSectionHeader
  kSectionFirstPrivate = 0x10000,  // 0x10000 and up: application-defined, never interpreted here
};

// Registered name of a section type ("metadata", "ndf-level", "ndf-chunk", "tensor-index",
// "tensor-info", "tensor-group", "ltc-table", "roughness", "flakes", "wang-info", "wang-edges", "wang-texels",
// "wang-tile-ndf", "glitter-info", "glitter-integrals", "shard-metadata", "shard-section",
// "image"); "private" for types >= kSectionFirstPrivate,
// "unknown" otherwise. sectionTypeFromString accepts the registered names and decimal or 0x-hex numbers.
const char* sectionTypeString(uint32_t type);
bool sectionTypeFromString(const std::string& name, uint32_t* type);

// One row of the section index, as stored (little-endian on disk; see SPEC.md).
struct SectionInfo {
  uint32_t type = 0;
  uint32_t codec = 0;  // Codec
  uint64_t key = 0;
  uint64_t offset = 0;       // from the start of the file, multiple of kSectionAlignment
  uint64_t stored_size = 0;  // bytes in the file
  uint64_t raw_size = 0;     // bytes after decoding
  uint64_t checksum = 0;     // XXH3-64 of the stored bytes
  uint32_t flags = 0;        // reserved, 0
  uint32_t reserved = 0;
};

// Header fields a reader exposes.
struct HeaderInfo {
  uint16_t version_major = 0;
  uint16_t version_minor = 0;
  uint32_t asset_kind = 0;
  uint64_t file_size = 0;
  uint32_t section_count = 0;
  uint64_t index_offset = 0;
  uint64_t file_checksum = 0;
};

// 64-bit and 128-bit content hashes (XXH3). Used for section checksums and for provenance hashes
// of input files. hash128Hex and hashFile128Hex return the prefixed text form
// "xxh3-128:<32 lowercase hex digits>" (high 64 bits first).
uint64_t hash64(const void* data, size_t size);
std::string hash128Hex(const void* data, size_t size);
// Hash of a whole file, streamed; returns kIoError if it cannot be read.
ContainerStatus hashFile128Hex(const std::string& path, std::string* hex_out);

// Writes a container. Sections are compressed and appended as they are added, so a producer
// never holds more than one section in memory; the index and header are written by finish().
// Output goes to an anonymous file in the same directory (format::AtomicFile; "<path>.tmp-<random>"
// where the file system has no anonymous files) that finish() puts in place at <path>; if finish()
// is not reached (error, destruction, abort()), nothing is left behind.
// Not thread-safe: one thread adds sections (compress in parallel upstream and add in a fixed order
// for deterministic bytes).
class Writer {
 public:
  Writer();
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Opens the temporary file next to `path`. zstd_level: 1..19 (default 9).
  ContainerStatus open(const std::string& path, AssetKind kind, int zstd_level = 9);
  // Appends one section. codec kZstd falls back to kRaw when compression does not shrink the data.
  ContainerStatus addSection(uint32_t type, uint64_t key, const void* data, size_t size, Codec codec = Codec::kZstd);
  // Appends one section whose stored bytes are already encoded (codec, raw_size as in the index;
  // e.g. copied from another container, or made by encodeSection()). The bytes are not decoded:
  // the caller vouches for them. Same rules on (type, key) and metadata as addSection.
  ContainerStatus addStoredSection(uint32_t type, uint64_t key, Codec codec, uint64_t raw_size, const void* stored,
                                   size_t stored_size);
  // Convenience for the JSON metadata section (must be added exactly once before finish()).
  ContainerStatus addMetadata(const std::string& json_utf8);
  // Writes index and header, flushes, renames to the final path.
  ContainerStatus finish();
  // Drops the temporary file. Called by the destructor if finish() did not succeed.
  void abort();
  // Path of the temporary file while open (for signal handlers that must unlink it); empty when
  // the temporary file is anonymous.
  const std::string& temporaryPath() const;
  // errno of the first failed write, sync or rename (EFBIG, ENOSPC, ...), 0 when none.
  int errorNumber() const;
  // The reason of a failure for messages: strerror(errorNumber()) when a write failed ("File too
  // large", "No space left on device"), else statusString(status).
  std::string errorString(ContainerStatus status) const;
  uint64_t bytesWritten() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Encodes section bytes exactly as Writer::addSection stores them at zstd_level (1..19): the
// same frame parameters, and raw when zstd does not shrink the data. *stored receives the stored
// bytes, *used the codec. Not thread-safe per encoder; one encoder per thread.
class SectionEncoder {
 public:
  explicit SectionEncoder(int zstd_level);
  ~SectionEncoder();
  SectionEncoder(const SectionEncoder&) = delete;
  SectionEncoder& operator=(const SectionEncoder&) = delete;
  ContainerStatus encode(const void* data, size_t size, Codec codec, std::vector<uint8_t>* stored, Codec* used);

 private:
  void* cctx_ = nullptr;
  int level_ = 9;
};

// Options of a reader. All limits apply before any allocation, so untrusted files cannot make the
// reader allocate or decompress more than these.
struct ReaderOptions {
  uint64_t max_raw_section_size = kDefaultMaxRawSectionSize;
  bool verify_file_checksum = false;  // hash the whole file on open (validate does; queries need not)
};

// One section's decoded bytes, front to back (Reader::openSectionStream).
class SectionStream {
 public:
  SectionStream();
  ~SectionStream();
  SectionStream(const SectionStream&) = delete;
  SectionStream& operator=(const SectionStream&) = delete;

  // The open section's raw_size and the bytes not yet read (0 when no section is open).
  uint64_t size() const;
  uint64_t remaining() const;
  // Copies the next min(size, remaining()) decoded bytes into dst. kDecompressFailed when the
  // frame turns out not to decode to exactly raw_size bytes (the call's bytes are then
  // unspecified, and later calls fail the same way); kInvalidArgument when nothing is open.
  ContainerStatus read(void* dst, size_t size);

 private:
  friend class Reader;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Reads a container with random access: open() reads and checks header and index only; each
// section is read, checksum-verified and decoded on request. Safe on untrusted input: every offset
// and size is checked against the file size and the limits above. const methods are thread-safe
// (they use positioned reads).
class Reader {
 public:
  Reader();
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  ContainerStatus open(const std::string& path, const ReaderOptions& options = {});
  // Reads from a caller-owned buffer that must outlive the reader (fuzzing, embedded assets).
  ContainerStatus openMemory(const void* data, size_t size, const ReaderOptions& options = {});
  void close();

  const HeaderInfo& header() const;
  AssetKind kind() const;
  // Sections in index order, including types this reader does not know.
  const std::vector<SectionInfo>& sections() const;
  // Index of the first section with this type (and key, if given), or -1.
  int find(uint32_t type) const;
  int find(uint32_t type, uint64_t key) const;

  // Reads section i into out (resized to raw_size): checks bounds, checksum and decoded size. For
  // zstd, the frame's recorded content size must equal raw_size and its blocks must be able to
  // produce that many bytes (from its block headers) BEFORE out is resized, so a small file declaring
  // a huge section costs at most its stored bytes (kDecompressFailed). A frame whose window exceeds
  // kMaxZstdWindowSize is refused (kTooLarge), as openSectionStream must, so that every reader
  // accepts the same files.
  ContainerStatus readSection(size_t i, std::vector<uint8_t>* out) const;
  // Same, into a caller buffer of exactly raw_size bytes (kInvalidArgument otherwise). Raw sections
  // are read straight into dst; zstd sections of a file reader go through a temporary buffer of
  // stored_size bytes (none for openMemory), plus zstd's decoding context.
  ContainerStatus readSectionInto(size_t i, void* dst, size_t dst_size) const;
  // Opens section i for reading front to back in bounded memory through `stream` (which any
  // earlier section it held is dropped from): the checks of readSection (checksum, codec, frame,
  // window) are made first, reading the stored bytes in 1 MiB pieces; the bytes are then decoded
  // as stream->read() asks for them. Memory: about 2 MiB plus, for zstd, its window (at most
  // kMaxZstdWindowSize; about 8 MiB at the writer's levels), whatever raw_size. Same statuses as
  // readSection; a zstd frame whose damage only decoding finds fails a later read(). The reader
  // must stay open and outlive the stream. Safe on untrusted input; streams of one reader may be
  // used from different threads, each stream from one.
  ContainerStatus openSectionStream(size_t i, SectionStream* stream) const;
  // Reads the stored (possibly compressed) bytes of section i without decoding.
  ContainerStatus readStored(size_t i, std::vector<uint8_t>* out) const;
  // The metadata JSON text (the single kSectionMetadata section). kTooLarge, before anything is
  // read, when its raw_size exceeds kMaxMetadataSize.
  ContainerStatus readMetadata(std::string* json_utf8) const;
  // Hashes every byte after the header and compares with the header's file checksum.
  ContainerStatus verifyFileChecksum() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Generic float image section (kSectionImage and any image-like section that uses it): a 32-byte
// little-endian header followed by width*height*channels float32 values, row-major, top row first.
struct ImageSectionHeader {
  uint32_t magic = 0x474D4947;  // "GIMG"
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t channels = 0;
  uint32_t layers = 1;  // images stacked one after another
  uint32_t flags = 0;
  uint64_t reserved = 0;
};
static_assert(sizeof(ImageSectionHeader) == 32, "ImageSectionHeader is 32 bytes");

}  // namespace glintbake::format
