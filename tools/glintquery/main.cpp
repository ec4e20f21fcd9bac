// SPDX-License-Identifier: Apache-2.0
// glintquery: answers P-NDF queries on a baked NDF asset (ndf-pyramid or tensor-ndf) through the
// runtime-lite, exactly as a renderer would see them: point values, the blended image of a
// footprint, and JSON-lines batches of point, range, sample, pdf and mass queries.
#include "commands.h"

int main(int argc, char** argv) {
  using namespace glintbake;
  cli::Tool tool(
      "glintquery",
      "Queries baked NDF assets through the runtime (point, image, batch; materialise: a wang-tiles grid region)");
  tool.addExample("glintquery point brushed.gbk --at 64,64 --sigma 4 --s 0.1,0",
                  "The P-NDF density of one footprint at one s-plane point.");
  tool.addExample("glintquery image brushed.gbk --at 64,64 --sigma 4 -o ndf.exr",
                  "The NDF image the runtime blends for that footprint.");
  tool.addExample("glintquery materialise floor.gbk --cells 0,0,8,8 -o region.exr",
                  "8 x 8 cells of a wang-tiles asset's grid as a normal map, for the reference evaluator.");
  CLI::App& app = tool.app();
  app.require_subcommand(1);
  app.fallthrough();

  glintquery::PointOptions point;
  glintquery::ImageOptions image;
  glintquery::BatchOptions batch;
  glintquery::MaterialiseOptions materialise;
  CLI::App* point_cmd = glintquery::addPointCommand(app, point);
  CLI::App* image_cmd = glintquery::addImageCommand(app, image);
  CLI::App* batch_cmd = glintquery::addBatchCommand(app, batch);
  CLI::App* materialise_cmd = glintquery::addMaterialiseCommand(app, materialise);

  return tool.run(argc, argv, [&](cli::Tool& t) {
    if (point_cmd->parsed()) return glintquery::runPoint(t, point);
    if (image_cmd->parsed()) return glintquery::runImage(t, image);
    if (batch_cmd->parsed()) return glintquery::runBatch(t, batch);
    if (materialise_cmd->parsed()) return glintquery::runMaterialise(t, materialise);
    throw cli::Error(cli::kExitBadArguments, "no command given: use point, image, batch or materialise (see --help)");
  });
}
