// SPDX-License-Identifier: Apache-2.0
// glintinfo diff: compares two containers section by section, matched by (type, key). Image-like
// sections are compared by metrics against tolerances, metadata as JSON (ignoring the generator
// version), everything else byte for byte.
#include "commands.h"
#include "container_access.h"

#include <glintbake/format/validate.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <utility>

namespace glintbake::glintinfo {
namespace {

struct ImageMetrics {
  double max_abs = 0.0;  // max |a - b| over all values (inf if a NaN pairs with a number)
  double rel_l2 = 0.0;   // ||a - b||_2 / ||a||_2 (0 when both are zero, inf when only a is)
};

// Values start after the 32-byte image header; both images have identical dimensions.
ImageMetrics compareImages(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  constexpr size_t kHeader = sizeof(format::ImageSectionHeader);
  const size_t count = (a.size() - kHeader) / 4;
  ImageMetrics m;
  double diff2 = 0.0, norm2 = 0.0;
  for (size_t i = 0; i < count; ++i) {
    float va, vb;
    std::memcpy(&va, a.data() + kHeader + 4 * i, 4);
    std::memcpy(&vb, b.data() + kHeader + 4 * i, 4);
    if (std::isnan(va) || std::isnan(vb)) {
      if (std::isnan(va) != std::isnan(vb)) m.max_abs = std::numeric_limits<double>::infinity();
      continue;
    }
    const double d = (std::isinf(va) || std::isinf(vb)) ? (va == vb ? 0.0 : std::numeric_limits<double>::infinity())
                                                        : double(va) - double(vb);
    m.max_abs = std::max(m.max_abs, std::abs(d));
    diff2 += d * d;
    if (std::isfinite(va)) norm2 += double(va) * double(va);
  }
  if (diff2 == 0.0) {
    m.rel_l2 = m.max_abs > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  } else {
    m.rel_l2 = norm2 > 0.0 ? std::sqrt(diff2 / norm2) : std::numeric_limits<double>::infinity();
  }
  return m;
}

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
    const auto da = readSectionOrThrow(*a, options.file_a, size_t(ia));
    const auto db = readSectionOrThrow(*b, options.file_b, size_t(ib));
    format::ImageSectionHeader ha, hb;
    if (format::parseImageSection(da.data(), da.size(), &ha) && format::parseImageSection(db.data(), db.size(), &hb)) {
      row["comparison"] = "image";
      if (ha.width != hb.width || ha.height != hb.height || ha.channels != hb.channels || ha.layers != hb.layers) {
        equal = false;
        row["detail"] = "dimensions differ";
        lines.push_back(label + ": image dimensions differ");
      } else {
        const ImageMetrics m = compareImages(da, db);
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
      equal = da == db;
      if (!equal) {
        size_t first = 0;
        while (first < std::min(da.size(), db.size()) && da[first] == db[first]) ++first;
        row["detail"] = "first difference at byte " + std::to_string(first);
        lines.push_back(label + ": bytes differ (sizes " + std::to_string(da.size()) + " and " +
                        std::to_string(db.size()) + ", first difference at byte " + std::to_string(first) + ")");
      }
    }
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
