// SPDX-License-Identifier: Apache-2.0
// glintinfo merge: joins the partial containers of a sharded bake (ndfgen/tensorpack --shard I/N)
// into the asset, byte-identical to the file one machine writes (formats/SPEC.md 10.9): ndfgen's
// parts by copying their sections in position order, tensorpack's by replaying its final assembly. Refuses,
// before writing anything, parts that do not belong together: another tool or version, other
// inputs or options, another shard count, a shard missing or given twice.
#include "commands.h"
#include "container_access.h"

#include <glintbake/bake/ndf/pyramid_builder.h>
#include <glintbake/bake/tensor/tensor_assembly.h>
#include <glintbake/bake/tensor/tensor_shard.h>
#include <glintbake/cli/container_output.h>
#include <glintbake/cli/exit_codes.h>
#include <glintbake/cli/tensor_asset.h>
#include <glintbake/format/kinds/partial.h>

#include <chrono>
#include <cstring>
#include <map>
#include <memory>
#include <vector>

namespace glintbake::glintinfo {
namespace {

using cli::Error;
using cli::Json;

struct Part {
  std::string path;
  std::unique_ptr<format::Reader> reader;
  Json meta, asset;
  std::string asset_metadata;  // the merged asset's metadata text
  int shard = 0;
};

Error invalid(const std::string& message) { return Error(cli::kExitInvalidInput, message); }

Part openPart(const std::string& path) {
  Part p;
  p.path = path;
  p.reader = openContainer(path);
  if (p.reader->kind() != format::AssetKind::kPartial) {
    throw invalid(path + ": not a partial container of a sharded bake (asset kind " +
                  format::assetKindString(p.reader->kind()) + ")");
  }
  if (format::ContainerStatus st = p.reader->verifyFileChecksum(); st != format::ContainerStatus::kOk)
    throw Error(cli::exitCodeOf(st), path + ": file checksum: " + format::statusString(st));
  p.meta = parseMetadata(readMetadataOrThrow(*p.reader, path));
  if (!p.meta.is_object() || !p.meta.contains("asset") || !p.meta["asset"].is_object())
    throw invalid(path + ": partial container without its shard description (metadata asset)");
  p.asset = p.meta["asset"];
  for (const char* key : {"shard", "shards", "positions", "zstd_level"}) {
    if (!p.asset.contains(key) || !p.asset[key].is_number_integer())
      throw invalid(path + ": shard description lacks '" + key + "'");
  }
  if (!p.asset.contains("asset_kind") || !p.asset["asset_kind"].is_string())
    throw invalid(path + ": shard description lacks 'asset_kind'");
  p.shard = p.asset["shard"].get<int>();
  const int idx = p.reader->find(format::kSectionShardMetadata, 0);
  if (idx < 0) throw invalid(path + ": partial container without the merged asset's metadata (shard-metadata)");
  const std::vector<uint8_t> text = readSectionOrThrow(*p.reader, path, size_t(idx));
  p.asset_metadata.assign(text.begin(), text.end());
  return p;
}

// The parameters of a part without its own shard number.
Json sharedParameters(const Part& p) {
  Json params = p.meta.value("parameters", Json::object());
  if (params.is_object()) params.erase("shard");
  return params;
}

// Throws when b does not come from the same bake as a, naming what differs.
void checkSameBake(const Part& a, const Part& b) {
  const std::string both = a.path + " and " + b.path;
  if (a.meta.value("generator", Json()) != b.meta.value("generator", Json()))
    throw invalid(both + " come from different tools or tool versions");
  if (a.meta.value("inputs", Json()) != b.meta.value("inputs", Json()))
    throw invalid(both + " are shards of bakes of different inputs (content hashes differ)");
  if (sharedParameters(a) != sharedParameters(b)) throw invalid(both + " are shards of bakes with different options");
  if (a.asset["shards"] != b.asset["shards"])
    throw invalid(both + " split the bake into different shard counts (" + a.asset["shards"].dump() + " and " +
                  b.asset["shards"].dump() + ")");
  if (a.asset["asset_kind"] != b.asset["asset_kind"] || a.asset["positions"] != b.asset["positions"] ||
      a.asset["zstd_level"] != b.asset["zstd_level"] || a.asset_metadata != b.asset_metadata ||
      a.asset.value("assembly", Json()) != b.asset.value("assembly", Json()) ||
      a.asset.value("units_total", Json()) != b.asset.value("units_total", Json()))
    throw invalid(both + " disagree on the merged asset (its layout or metadata)");
}

// One section of a part: its header and where its stored bytes are.
struct Held {
  size_t part = 0, section = 0;
  format::ShardSectionHeader header;
};

format::ShardSectionHeader readHeader(const Part& p, size_t i) {
  const format::SectionInfo& s = p.reader->sections()[i];
  if (s.raw_size < sizeof(format::ShardSectionHeader))
    throw invalid(p.path + ": shard-section " + std::to_string(s.key) + " is truncated");
  std::vector<uint8_t> bytes = readSectionOrThrow(*p.reader, p.path, i);
  format::ShardSectionHeader h;
  std::memcpy(&h, bytes.data(), sizeof(h));
  if (const char* why = format::checkShardSectionHeader(h, s.raw_size))
    throw invalid(p.path + ": " + why + " (position " + std::to_string(s.key) + ")");
  return h;
}

// The merge's one-line summary, or its --json.
void printSummary(cli::Tool& t, const std::string& output, format::AssetKind kind, int shards, uint64_t sections,
                  uint64_t bytes, double seconds) {
  if (t.common().json) {
    Json doc;
    doc["command"] = "merge";
    doc["output"] = cli::baseName(output);
    doc["asset_kind"] = format::assetKindString(kind);
    doc["shards"] = shards;
    doc["sections"] = sections;
    doc["file_bytes"] = bytes;
    doc["seconds"] = seconds;
    t.printJson(doc);
  } else {
    t.info("wrote " + output + ": " + std::string(format::assetKindString(kind)) + " merged from " +
           std::to_string(shards) + " shards, " + std::to_string(sections) + " sections, " + std::to_string(bytes) +
           " bytes");
  }
}

// The level records every part holds (shard-levels), identical in all of them.
std::vector<format::NdfLevelRecord> readLevels(const std::vector<Part>& parts) {
  std::vector<uint8_t> first;
  for (size_t i = 0; i < parts.size(); ++i) {
    const int idx = parts[i].reader->find(format::kSectionShardLevels, 0);
    if (idx < 0) throw invalid(parts[i].path + ": replayed partial without its level records (shard-levels)");
    std::vector<uint8_t> bytes = readSectionOrThrow(*parts[i].reader, parts[i].path, size_t(idx));
    if (i == 0) {
      first = std::move(bytes);
    } else if (bytes != first) {
      throw invalid(parts[0].path + " and " + parts[i].path + " disagree on the merged asset (its levels)");
    }
  }
  const size_t n = first.size() / sizeof(format::NdfLevelRecord);
  if (n == 0 || n > size_t(bake::ndf::kMaxPyramidLevels) || first.size() % sizeof(format::NdfLevelRecord) != 0)
    throw invalid(parts[0].path + ": shard-levels section of the wrong size");
  std::vector<format::NdfLevelRecord> levels(n);
  std::memcpy(static_cast<void*>(levels.data()), first.data(), first.size());
  return levels;
}

// Replayed partials (tensorpack --shard): every unit's results, in the asset's order, through the
// final assembly the one-machine bake uses (TensorAssembler, cli::finishTensorAsset).
int mergeReplayed(cli::Tool& t, const MergeOptions& options, const std::vector<Part>& parts, format::AssetKind kind,
                  std::chrono::steady_clock::time_point t0) {
  const Part& first = parts.front();
  if (kind != format::AssetKind::kTensorNdf)
    throw invalid(first.path + ": replayed partials of a " + format::assetKindString(kind) + " asset");
  bake::tensor::TensorPackOptions pack;
  cli::TensorAssetEnd end;
  bool flakes = false;
  try {
    cli::readTensorShardAssembly(first.asset["assembly"], &pack, &end, &flakes);
  } catch (const Error& e) {
    throw invalid(first.path + ": " + e.what());
  }
  if (!first.asset.contains("units_total") || !first.asset["units_total"].is_number_unsigned())
    throw invalid(first.path + ": shard description lacks 'units_total'");
  const uint64_t units_total = first.asset["units_total"].get<uint64_t>();
  const std::vector<format::NdfLevelRecord> levels = readLevels(parts);

  // Who holds each unit: exactly one part.
  std::map<uint64_t, std::pair<size_t, size_t>> holder;
  for (size_t pi = 0; pi < parts.size(); ++pi) {
    const auto& sections = parts[pi].reader->sections();
    for (size_t i = 0; i < sections.size(); ++i) {
      if (sections[i].type == format::kSectionShardSection)
        throw invalid(parts[pi].path + ": a replayed partial holds positioned sections");
      if (sections[i].type != format::kSectionShardUnit) continue;
      const uint64_t unit = sections[i].key;
      if (unit >= units_total)
        throw invalid(parts[pi].path + ": unit " + std::to_string(unit) + " beyond the bake's " +
                      std::to_string(units_total));
      auto [it, fresh] = holder.emplace(unit, std::make_pair(pi, i));
      if (!fresh)
        throw invalid("unit " + std::to_string(unit) + " is held by both " + parts[it->second.first].path + " and " +
                      parts[pi].path);
    }
  }
  auto unitBytes = [&](uint64_t unit, const std::string& what) {
    const auto it = holder.find(unit);
    if (it == holder.end()) throw invalid("no part holds unit " + std::to_string(unit) + " (" + what + ")");
    const Part& p = parts[it->second.first];
    return readSectionOrThrow(*p.reader, p.path, it->second.second);
  };
  uint64_t needed = flakes ? 1 : 0;
  for (const format::NdfLevelRecord& rec : levels) needed += uint64_t(rec.regions_x) * rec.regions_y;
  if (needed > units_total) throw invalid(first.path + ": the levels hold more units than the bake has");

  cli::ContainerOutput out(t, options.output, kind, first.asset["zstd_level"].get<int>());
  bake::tensor::TensorPackReport report;
  bake::tensor::TensorAssembler assembler(out.writer(), pack, report);
  auto check = [&](bake::BakeStatus s, const std::string& where) {
    if (!s)
      throw Error(s.error().code == bake::ErrorCode::kIo ? cli::kExitIo : cli::kExitInvalidInput,
                  where + ": " + s.error().message);
  };
  uint64_t unit = 0;
  for (const format::NdfLevelRecord& rec : levels) {
    const std::string level = "level " + std::to_string(rec.level);
    check(assembler.level(rec), level);
    for (uint32_t r = 0; r < rec.regions_x * rec.regions_y; ++r, ++unit) {
      const std::string what = "region " + std::to_string(r) + " of " + level;
      const std::vector<uint8_t> bytes = unitBytes(unit, what);
      check(bake::tensor::replayTensorRegion(bytes.data(), bytes.size(), assembler), "unit " + std::to_string(unit));
    }
    check(assembler.endLevel(), level);
  }
  check(assembler.finish(), "the merged asset");
  // Units beyond the levels the bake reached hold nothing; the flakes are the last unit.
  for (const auto& [u, at] : holder) {
    if (u >= unit && !(flakes && u == units_total - 1))
      throw invalid(parts[at.first].path + ": unit " + std::to_string(u) + " beyond the levels the bake reached");
  }
  std::vector<uint8_t> flake_section;
  if (flakes) flake_section = unitBytes(units_total - 1, "the flakes");
  const Json inputs = first.meta.value("inputs", Json::array());
  end.label = inputs.is_array() && !inputs.empty() && inputs[0].contains("name") && inputs[0]["name"].is_string()
                  ? inputs[0]["name"].get<std::string>()
                  : options.output;
  const Json metadata = Json::parse(first.asset_metadata, nullptr, false);
  if (!metadata.is_object() || !metadata.contains("asset"))
    throw invalid(first.path + ": the merged asset's metadata is not an object with 'asset'");
  const cli::TensorAssetResult done = cli::finishTensorAsset(out.writer(), report, &flake_section, metadata, end);
  out.finish(done.metadata);
  for (const std::string& w : done.warnings) t.warning(end.label + ": " + w);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Levels and indexes, groups, the info record, the flakes and the metadata.
  const uint64_t sections = 2 * report.levels.size() + report.groups + 1 + (done.flake_bytes > 0 ? 1 : 0) + 1;
  const int shards = first.asset["shards"].get<int>();
  printSummary(t, options.output, kind, shards, sections, out.bytesWritten(), seconds);
  return cli::kExitOk;
}

}  // namespace

CLI::App* addMergeCommand(CLI::App& app, MergeOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "merge", "Joins the partial containers of a sharded bake into the asset (byte-identical to one machine's bake)");
  cmd->add_option("parts", options.parts, "Every shard's partial container (any order)")->required();
  cmd->add_option("-o,--output", options.output, "The merged asset")->required();
  return cmd;
}

int runMerge(cli::Tool& t, const MergeOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Part> parts;
  for (const std::string& path : options.parts) parts.push_back(openPart(path));
  const Part& first = parts.front();
  const int shards = first.asset["shards"].get<int>();
  for (size_t i = 1; i < parts.size(); ++i) checkSameBake(first, parts[i]);
  // Every shard once.
  std::vector<int> given(size_t(std::max(shards, 0)), -1);
  for (size_t i = 0; i < parts.size(); ++i) {
    const int s = parts[i].shard;
    if (s < 0 || s >= shards) throw invalid(parts[i].path + ": shard " + std::to_string(s) + " out of range");
    if (given[size_t(s)] >= 0)
      throw invalid("shard " + std::to_string(s) + "/" + std::to_string(shards) + " given twice (" +
                    parts[size_t(given[size_t(s)])].path + " and " + parts[i].path + ")");
    given[size_t(s)] = int(i);
  }
  for (int s = 0; s < shards; ++s) {
    if (given[size_t(s)] < 0)
      throw invalid("shard " + std::to_string(s) + "/" + std::to_string(shards) + " missing (" +
                    std::to_string(parts.size()) + " of " + std::to_string(shards) + " parts given)");
  }
  format::AssetKind kind = format::AssetKind::kUnknown;
  if (!format::assetKindFromString(first.asset["asset_kind"].get<std::string>(), &kind) ||
      kind == format::AssetKind::kPartial)
    throw invalid(first.path + ": unknown merged asset kind " + first.asset["asset_kind"].dump());

  if (first.asset.contains("assembly")) return mergeReplayed(t, options, parts, kind, t0);

  // Who holds each position: one owner, or (common sections) every part with the same bytes.
  const uint64_t positions = first.asset["positions"].get<uint64_t>();
  if (positions > format::kMaxSectionCount) throw invalid(first.path + ": too many positions");
  std::vector<Held> owner(static_cast<size_t>(positions));
  std::vector<int> holders(size_t(positions), 0), commons(size_t(positions), 0);
  for (size_t pi = 0; pi < parts.size(); ++pi) {
    const auto& sections = parts[pi].reader->sections();
    for (size_t i = 0; i < sections.size(); ++i) {
      if (sections[i].type != format::kSectionShardSection) continue;
      const uint64_t pos = sections[i].key;
      if (pos >= positions)
        throw invalid(parts[pi].path + ": shard-section at position " + std::to_string(pos) + " beyond the asset's " +
                      std::to_string(positions));
      const format::ShardSectionHeader h = readHeader(parts[pi], i);
      const bool common = (h.flags & format::kShardSectionCommon) != 0;
      Held& o = owner[size_t(pos)];
      if (holders[size_t(pos)] > 0) {
        const Held& prev = o;
        const bool prev_common = (prev.header.flags & format::kShardSectionCommon) != 0;
        const format::SectionInfo& a = parts[prev.part].reader->sections()[prev.section];
        if (!common || !prev_common || a.checksum != sections[i].checksum || a.raw_size != sections[i].raw_size)
          throw invalid("position " + std::to_string(pos) + " is held by both " + parts[prev.part].path + " and " +
                        parts[pi].path);
      } else {
        o = Held{pi, i, h};
      }
      ++holders[size_t(pos)];
      commons[size_t(pos)] += common ? 1 : 0;
    }
  }
  for (uint64_t pos = 0; pos < positions; ++pos) {
    if (holders[size_t(pos)] == 0)
      throw invalid("no part holds position " + std::to_string(pos) + " of the merged asset");
    if (commons[size_t(pos)] > 0 && commons[size_t(pos)] != int(parts.size()))
      throw invalid("position " + std::to_string(pos) + " is common but held by only " +
                    std::to_string(commons[size_t(pos)]) + " of " + std::to_string(parts.size()) + " parts");
  }

  // Copy the stored bytes in position order; the metadata last, as the tools write it.
  cli::ContainerOutput out(t, options.output, kind, first.asset["zstd_level"].get<int>());
  for (uint64_t pos = 0; pos < positions; ++pos) {
    const Held& o = owner[size_t(pos)];
    const std::vector<uint8_t> bytes = readSectionOrThrow(*parts[o.part].reader, parts[o.part].path, o.section);
    const format::ShardSectionHeader& h = o.header;
    if (format::ContainerStatus st =
            out.writer().addStoredSection(h.type, h.key, format::Codec(h.codec), h.raw_size,
                                          bytes.data() + sizeof(format::ShardSectionHeader), size_t(h.stored_size));
        st != format::ContainerStatus::kOk) {
      if (st == format::ContainerStatus::kInvalidArgument)
        throw invalid(parts[o.part].path + ": position " + std::to_string(pos) + " repeats section (" +
                      typeLabel(h.type) + ", " + std::to_string(h.key) + ")");
      throw Error(cli::kExitIo, "cannot write " + options.output + ": " + out.writer().errorString(st));
    }
  }
  out.finishText(first.asset_metadata);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  printSummary(t, options.output, kind, shards, positions + 1, out.bytesWritten(), seconds);
  return cli::kExitOk;
}

}  // namespace glintbake::glintinfo
