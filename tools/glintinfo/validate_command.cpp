// glintinfo validate: every check of formats/SPEC.md with stable message ids.
#include "commands.h"
#include "container_access.h"

#include <glintbake/format/validate.h>

#include <cstdio>

namespace glintbake::glintinfo {

CLI::App* addValidateCommand(CLI::App& app, ValidateOptions& options) {
  CLI::App* cmd = app.add_subcommand(
      "validate", "Check structure, checksums, payloads and metadata; print error-NNNN/warning-NNNN lines");
  cmd->add_option("file", options.file, "Container file (.gbk)")->required();
  cmd->footer("Exit codes: 0 valid (warnings allowed), 2 unreadable, 3 invalid, 5 newer major version.");
  return cmd;
}

int runValidate(cli::Tool& tool, const ValidateOptions& options) {
  const format::ValidationReport report = format::validateFile(options.file);
  if (report.status == format::ContainerStatus::kIoError && !report.messages.empty() && report.messages[0].id == 1001) {
    throw cli::Error(cli::kExitIo, "cannot read " + options.file);
  }

  if (tool.common().json) {
    cli::Json messages = cli::Json::array();
    for (const auto& m : report.messages) {
      messages.push_back({{"id", m.id}, {"severity", format::severityString(m.severity)}, {"message", m.message}});
    }
    tool.printJson({{"file", cli::baseName(options.file)},
                    {"valid", report.valid()},
                    {"errors", report.errorCount()},
                    {"warnings", report.warningCount()},
                    {"messages", messages}});
  } else if (!tool.common().quiet) {
    for (const auto& m : report.messages) {
      std::printf("%s-%04d: %s\n", format::severityString(m.severity), m.id, m.message.c_str());
    }
    std::printf("%s: %s (%zu errors, %zu warnings)\n", options.file.c_str(), report.valid() ? "valid" : "invalid",
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
  throw cli::Error(code, options.file + " is not valid: error-" + std::to_string(first->id) + ": " + first->message);
}

}  // namespace glintbake::glintinfo
