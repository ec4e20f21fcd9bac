// SPDX-License-Identifier: Apache-2.0
// glintinfo diff: compares two containers section by section, matched by (type, key). Image-like
// sections are compared by metrics against tolerances, metadata as JSON (ignoring the generator
// version), everything else byte for byte.
#include "commands.h"
#include "container_access.h"

#include <glintbake/cli/exit_codes.h>
#include <glintbake/format/validate.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace glintbake::glintinfo {
namespace {

constexpr size_t kPiece = size_t(1) << 20;  // bytes of each section held at a time

struct ImageMetrics {
  double max_abs = 0.0;  // max |a - b| over all values (inf if a NaN pairs with a number)
  double rel_l2 = 0.0;   // ||a - b||_2 / ||a||_2 (0 when both are zero, inf when only a is)
};

// Accumulates the metrics over the values of two images of identical dimensions, fed in order in
// pieces of whole floats.
class ImageComparison {
 public:
  void add(const uint8_t* a, const uint8_t* b, size_t bytes) {
    for (size_t i = 0; i + 4 <= bytes; i += 4) {
      float va, vb;
      std::memcpy(&va, a + i, 4);
      std::memcpy(&vb, b + i, 4);
      if (std::isnan(va) || std::isnan(vb)) {
        if (std::isnan(va) != std::isnan(vb)) max_abs_ = std::numeric_limits<double>::infinity();
        continue;
      }
      const double d = (std::isinf(va) || std::isinf(vb)) ? (va == vb ? 0.0 : std::numeric_limits<double>::infinity())
                                                          : double(va) - double(vb);
      max_abs_ = std::max(max_abs_, std::abs(d));
      diff2_ += d * d;
      if (std::isfinite(va)) norm2_ += double(va) * double(va);
    }
  }
  ImageMetrics metrics() const {
    ImageMetrics m;
    m.max_abs = max_abs_;
    if (diff2_ == 0.0) {
      m.rel_l2 = max_abs_ > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
    } else {
      m.rel_l2 = norm2_ > 0.0 ? std::sqrt(diff2_ / norm2_) : std::numeric_limits<double>::infinity();
    }
    return m;
  }

 private:
  double max_abs_ = 0.0, diff2_ = 0.0, norm2_ = 0.0;
};

// Section ia of A and ib of B, decoded in step a piece at a time (never whole). Failures are
// reported as reading A whole and then B whole would report them: a failure of B's only once A
// has been read to its end without one. Every comparison reads both to their ends, so damage
// anywhere in either fails the diff whatever the verdict.
class SectionPair {
 public:
  SectionPair(const format::Reader& a, const std::string& path_a, size_t ia, const format::Reader& b,
              const std::string& path_b, size_t ib)
      : path_a_(path_a), path_b_(path_b), ia_(ia), ib_(ib), scratch_(kPiece) {
    if (const format::ContainerStatus status = a.openSectionStream(ia, &a_); status != format::ContainerStatus::kOk)
      fail(path_a_, ia_, status);
    if (const format::ContainerStatus status = b.openSectionStream(ib, &b_); status != format::ContainerStatus::kOk)
      failB(status);
  }
  uint64_t sizeA() const { return a_.size(); }
  uint64_t sizeB() const { return b_.size(); }
  uint64_t remainingA() const { return a_.remaining(); }
  uint64_t remainingB() const { return b_.remaining(); }
  void readA(uint8_t* dst, size_t n) {
    if (const format::ContainerStatus status = a_.read(dst, n); status != format::ContainerStatus::kOk)
      fail(path_a_, ia_, status);
  }
  void readB(uint8_t* dst, size_t n) {
    if (const format::ContainerStatus status = b_.read(dst, n); status != format::ContainerStatus::kOk) failB(status);
  }
  // Reads what is left of both.
  void finish() {
    finishA();
    while (b_.remaining() > 0) readB(scratch_.data(), size_t(std::min<uint64_t>(kPiece, b_.remaining())));
  }

 private:
  [[noreturn]] static void fail(const std::string& path, size_t i, format::ContainerStatus status) {
    throw cli::Error(cli::exitCodeOf(status),
                     path + ": section " + std::to_string(i) + ": " + sectionReadError(status));
  }
  [[noreturn]] void failB(format::ContainerStatus status) {
    finishA();
    fail(path_b_, ib_, status);
  }
  void finishA() {
    while (a_.remaining() > 0) readA(scratch_.data(), size_t(std::min<uint64_t>(kPiece, a_.remaining())));
  }

  const std::string& path_a_;
  const std::string& path_b_;
  size_t ia_, ib_;
  format::SectionStream a_, b_;
  std::vector<uint8_t> scratch_;
};

// Metadata as JSON with the generator version removed. Metadata that is not JSON within the
// nesting limit is invalid input, never "the same" as another such file.
cli::Json comparableMetadata(const format::Reader& reader, const std::string& path) {
  const std::string text = readMetadataOrThrow(reader, path);
  cli::Json doc = parseMetadata(text);
  if (doc.is_null()) {
    throw cli::Error(cli::kExitInvalidInput, path + ": error-5003: metadata is not UTF-8 JSON nested at most " +
                                                 std::to_string(format::kMaxJsonDepth) + " levels");
  }
  if (doc.is_object() && doc.contains("generator") && doc["generator"].is_object()) doc["generator"].erase("version");
  return doc;
}

cli::Json jsonNumber(double v) { return std::isfinite(v) ? cli::Json(v) : cli::Json("inf"); }

}  // namespace

CLI::App* addDiffCommand(CLI::App& app, DiffOptions& options) {
  CLI::App* cmd = app.add_subcommand("diff", "Compare two containers section by section (exit 7 if they differ)");
  cmd->add_option("a", options.file_a, "First container")->required();
  cmd->add_option("b", options.file_b, "Second container")->required();
  cmd->add_option("--rel-tol", options.rel_tol,
                  "Image sections match when their relative L2 difference is at most this")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--abs-tol", options.abs_tol, "... or when their largest absolute difference is at most this")
      ->check(CLI::NonNegativeNumber);
  cmd->footer("Exit codes: 0 same within tolerance, 7 different, 2 unreadable, 3 invalid, 5 newer major version.");
  return cmd;
}

int runDiff(cli::Tool& tool, const DiffOptions& options) {
  const auto a = openContainer(options.file_a);
  const auto b = openContainer(options.file_b);

  cli::Json rows = cli::Json::array();
  bool same = true;
  std::vector<std::string> lines;

  if (a->header().asset_kind != b->header().asset_kind) {
    same = false;
    lines.push_back(std::string("asset kind differs: ") + format::assetKindString(a->kind()) + " vs " +
                    format::assetKindString(b->kind()));
  }

  // Sections in the order of A, then those only in B, each pair identified by (type, key).
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < a->sections().size(); ++i) {
    const auto& s = a->sections()[i];
    pairs.emplace_back(int(i), b->find(s.type, s.key));
  }
  for (size_t j = 0; j < b->sections().size(); ++j) {
    const auto& s = b->sections()[j];
    if (a->find(s.type, s.key) < 0) pairs.emplace_back(-1, int(j));
  }

  for (const auto& [ia, ib] : pairs) {
    const format::SectionInfo& s = ia >= 0 ? a->sections()[size_t(ia)] : b->sections()[size_t(ib)];
    cli::Json row{{"type", s.type}, {"type_name", format::sectionTypeString(s.type)}, {"key", s.key}};
    const std::string label = typeLabel(s.type) + " (" + keyLabel(s.type, s.key) + ")";
    if (ia < 0 || ib < 0) {
      row["status"] = ia < 0 ? "only-b" : "only-a";
      row["comparison"] = "none";
      lines.push_back(label + ": only in " + (ia < 0 ? options.file_b : options.file_a));
      same = false;
      rows.push_back(row);
      continue;
    }
    bool equal = true;
    if (s.type == format::kSectionMetadata) {
      row["comparison"] = "metadata";
      equal = comparableMetadata(*a, options.file_a) == comparableMetadata(*b, options.file_b);
      if (!equal) lines.push_back(label + ": metadata differs (generator version ignored)");
      row["status"] = equal ? "same" : "different";
      same = same && equal;
      rows.push_back(row);
      continue;
    }
    // Both sections stream past in step, a piece at a time: their first bytes decide between an
    // image and a byte comparison.
    SectionPair pair(*a, options.file_a, size_t(ia), *b, options.file_b, size_t(ib));
    std::vector<uint8_t> piece_a(kPiece), piece_b(kPiece);
    const size_t head_a = size_t(std::min<uint64_t>(pair.sizeA(), sizeof(format::ImageSectionHeader)));
    const size_t head_b = size_t(std::min<uint64_t>(pair.sizeB(), sizeof(format::ImageSectionHeader)));
    pair.readA(piece_a.data(), head_a);
    pair.readB(piece_b.data(), head_b);
    format::ImageSectionHeader ha, hb;
    if (format::parseImageSectionHead(piece_a.data(), head_a, pair.sizeA(), &ha) &&
        format::parseImageSectionHead(piece_b.data(), head_b, pair.sizeB(), &hb)) {
      row["comparison"] = "image";
      if (ha.width != hb.width || ha.height != hb.height || ha.channels != hb.channels || ha.layers != hb.layers) {
        equal = false;
        row["detail"] = "dimensions differ";
        lines.push_back(label + ": image dimensions differ");
      } else {
        ImageComparison comparison;  // same dimensions, so the same size
        while (pair.remainingA() > 0) {
          const size_t n = size_t(std::min<uint64_t>(kPiece, pair.remainingA()));
          pair.readA(piece_a.data(), n);
          pair.readB(piece_b.data(), n);
          comparison.add(piece_a.data(), piece_b.data(), n);
        }
        const ImageMetrics m = comparison.metrics();
        equal = m.max_abs <= options.abs_tol || m.rel_l2 <= options.rel_tol;
        row["max_abs_diff"] = jsonNumber(m.max_abs);
        row["rel_l2"] = jsonNumber(m.rel_l2);
        if (!equal) {
          char buffer[160];
          std::snprintf(buffer, sizeof buffer, ": max abs diff %.6g, relative L2 %.6g (tolerances %g abs, %g rel)",
                        m.max_abs, m.rel_l2, options.abs_tol, options.rel_tol);
          lines.push_back(label + buffer);
        }
      }
    } else {
      row["comparison"] = "bytes";
      // The first difference within the common length; the common length when there is none.
      const uint64_t common = std::min(pair.sizeA(), pair.sizeB());
      uint64_t compared = 0;
      bool differ = false;
      auto compare = [&](size_t n) {
        for (size_t k = 0; k < n && !differ; ++k) {
          if (piece_a[k] != piece_b[k]) {
            differ = true;
            compared += k;
          }
        }
        if (!differ) compared += n;
      };
      compare(std::min(head_a, head_b));
      while (!differ && compared < common) {
        const size_t n = size_t(std::min<uint64_t>(kPiece, common - compared));
        pair.readA(piece_a.data(), n);
        pair.readB(piece_b.data(), n);
        compare(n);
      }
      equal = !differ && pair.sizeA() == pair.sizeB();
      if (!equal) {
        const std::string first = std::to_string(compared);
        row["detail"] = "first difference at byte " + first;
        lines.push_back(label + ": bytes differ (sizes " + std::to_string(pair.sizeA()) + " and " +
                        std::to_string(pair.sizeB()) + ", first difference at byte " + first + ")");
      }
    }
    pair.finish();
    row["status"] = equal ? "same" : "different";
    same = same && equal;
    rows.push_back(row);
  }

  if (tool.common().json) {
    tool.printJson({{"file_a", cli::baseName(options.file_a)},
                    {"file_b", cli::baseName(options.file_b)},
                    {"same", same},
                    {"asset_kind_a", format::assetKindString(a->kind())},
                    {"asset_kind_b", format::assetKindString(b->kind())},
                    {"rel_tol", options.rel_tol},
                    {"abs_tol", options.abs_tol},
                    {"sections", rows}});
  } else if (!tool.common().quiet) {
    for (const auto& line : lines) std::printf("%s\n", line.c_str());
    std::printf("%s\n", same ? "same" : "different");
  }
  return same ? cli::kExitOk : cli::kExitDifferences;
}

}  // namespace glintbake::glintinfo
