// glintref: the reference P-NDF evaluator of glintbake (the slow, obviously-correct definition
// every fast path is checked against): point values, bin-averaged NDF images and samples.
#include "commands.h"

int main(int argc, char** argv) {
  using namespace glintbake;
  cli::Tool tool("glintref", "Reference P-NDF of a normal map: point values, bin-averaged images, samples");
  CLI::App& app = tool.app();
  // Common options (--json, --quiet, ...) may follow the subcommand.
  app.fallthrough();
  app.require_subcommand(1);

  glintref::NdfOptions ndf;
  glintref::ImageOptions image;
  glintref::SampleOptions sample;
  CLI::App* ndf_cmd = glintref::addNdfCommand(app, ndf);
  CLI::App* image_cmd = glintref::addImageCommand(app, image);
  CLI::App* sample_cmd = glintref::addSampleCommand(app, sample);

  return tool.run(argc, argv, [&](cli::Tool& t) {
    if (ndf_cmd->parsed()) return glintref::runNdf(t, ndf);
    if (image_cmd->parsed()) return glintref::runImage(t, image);
    if (sample_cmd->parsed()) return glintref::runSample(t, sample);
    throw cli::Error(cli::kExitBadArguments, "no command given");
  });
}
