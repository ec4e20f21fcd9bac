// SPDX-License-Identifier: Apache-2.0
// glintinfo validate: every check of formats/SPEC.md with stable message ids.
#include "commands.h"
#include "container_access.h"

#include <glintbake/cli/stdin_input.h>
#include <glintbake/format/validate.h>
#include <glintbake/runtime/ltc.h>
#include <glintbake/runtime/ndf_source.h>

#include <cstdio>
#include <memory>

namespace glintbake::glintinfo {
namespace {

// 6004/6005 (formats/SPEC.md section 8): a structurally sound container of a kind the runtime
// loads must also pass the runtime's own layout and record checks, by the runtime's own loader
// (one implementation), so that validate passes exactly the files a renderer can open.
void checkWithRuntime(const std::string& path, format::ValidationReport* report) {
  if (report->status != format::ContainerStatus::kOk) return;
  format::Reader reader;
  if (reader.open(path) != format::ContainerStatus::kOk) return;
  const format::AssetKind kind = reader.kind();
  reader.close();
  runtime::RuntimeStatus status = runtime::RuntimeStatus::kOk;
  int id = 0;
  if (kind == format::AssetKind::kNdfPyramid || kind == format::AssetKind::kTensorNdf ||
      kind == format::AssetKind::kWangTiles || kind == format::AssetKind::kTinyExample ||
      kind == format::AssetKind::kGlitter) {
    std::unique_ptr<runtime::NdfSource> ndf;
    status = runtime::openNdfAsset(path.c_str(), &ndf);
    id = 6004;
  } else if (kind == format::AssetKind::kLtcTable) {
    runtime::LtcTable table;
    status = table.open(path.c_str());
    id = 6005;
  }
  if (status == runtime::RuntimeStatus::kOk || status == runtime::RuntimeStatus::kOutOfMemory) return;
  report->messages.push_back({id, format::Severity::kError,
                              std::string("the runtime refuses this ") + format::assetKindString(kind) +
                                  " asset: " + runtime::statusString(status)});
}

}  // namespace

CLI::App* addValidateCommand(CLI::App& app, ValidateOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "validate", "Check structure, checksums, payloads and metadata; print error-NNNN/warning-NNNN lines");
  cmd->add_option("file", options.file, "Container file (.gbk)")->required();
  cmd->footer("Exit codes: 0 valid (warnings allowed), 2 unreadable, 3 invalid, 5 newer major version.");
  return cmd;
}

int runValidate(cli::Tool& tool, const ValidateOptions& arguments) {
  ValidateOptions options = arguments;
  options.file = cli::resolveInput(arguments.file);
  format::ValidationReport report = format::validateFile(options.file);
  if (report.status == format::ContainerStatus::kIoError && !report.messages.empty() && report.messages[0].id == 1001) {
    throw cli::Error(cli::kExitIo, "cannot read " + arguments.file);
  }
  checkWithRuntime(options.file, &report);

  if (tool.common().json) {
    cli::Json messages = cli::Json::array();
    for (const auto& m : report.messages) {
      messages.push_back({{"id", m.id}, {"severity", format::severityString(m.severity)}, {"message", m.message}});
    }
    tool.printJson({{"file", cli::baseName(arguments.file)},
                    {"valid", report.valid()},
                    {"errors", report.errorCount()},
                    {"warnings", report.warningCount()},
                    {"messages", messages}});
  } else if (!tool.common().quiet) {
    for (const auto& m : report.messages) {
      std::printf("%s-%04d: %s\n", format::severityString(m.severity), m.id, m.message.c_str());
    }
    std::printf("%s: %s (%zu errors, %zu warnings)\n", arguments.file.c_str(), report.valid() ? "valid" : "invalid",
                report.errorCount(), report.warningCount());
  }

  if (report.valid()) return cli::kExitOk;
  const format::ValidationMessage* first = nullptr;
  for (const auto& m : report.messages) {
    if (m.severity == format::Severity::kError) {
      first = &m;
      break;
    }
  }
  const int code = report.status == format::ContainerStatus::kUnsupportedVersion ? cli::kExitUnsupported
                   : report.status == format::ContainerStatus::kIoError          ? cli::kExitIo
                                                                                 : cli::kExitInvalidInput;
  throw cli::Error(code, arguments.file + " is not valid: error-" + std::to_string(first->id) + ": " + first->message);
}

}  // namespace glintbake::glintinfo
