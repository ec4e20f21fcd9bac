// SPDX-License-Identifier: Apache-2.0
// glintref: the reference P-NDF evaluator of glintbake (the slow, obviously-correct definition
// every fast path is checked against): point values, bin-averaged NDF images and samples, a
// reference renderer and image comparison.
#include "commands.h"

int main(int argc, char** argv) {
  using namespace glintbake;
  cli::Tool tool("glintref",
                 "Reference P-NDF of a normal map: point values, bin-averaged images, samples, renders, comparisons; "
                 "procedural glitter");
  tool.addExample("glintref ndf map.png --at 64,64 --sigma 4 --s 0.1,0",
                  "The reference P-NDF of a normal map at one point.");
  tool.addExample("glintref render scene.json -o render.exr --asset brushed.gbk",
                  "Render a scene with a baked asset on its material.");
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
  glintref::RenderOptions render;
  glintref::CompareOptions compare;
  CLI::App* render_cmd = glintref::addRenderCommand(app, render);
  CLI::App* compare_cmd = glintref::addCompareCommand(app, compare);
  glintref::GlitterOptions glitter;
  CLI::App* glitter_cmd = glintref::addGlitterCommand(app, glitter);

  return tool.run(argc, argv, [&](cli::Tool& t) {
    if (ndf_cmd->parsed()) return glintref::runNdf(t, ndf);
    if (image_cmd->parsed()) return glintref::runImage(t, image);
    if (sample_cmd->parsed()) return glintref::runSample(t, sample);
    if (render_cmd->parsed()) return glintref::runRender(t, render);
    if (compare_cmd->parsed()) return glintref::runCompare(t, compare);
    if (glitter_cmd->parsed()) return glintref::runGlitter(t, glitter);
    throw cli::Error(cli::kExitBadArguments, "no command given");
  });
}
