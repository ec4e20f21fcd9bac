// What the exact small-footprint evaluator needs of a surface: the (n_x, n_y) of every texel of a
// grid, and how the grid continues beyond its edges. A normal map implements it today; a Wang-tile
// grid or a transformed tiny example supplies its texels through the same interface, so every asset
// kind shares one flake evaluator (flake_ndf.h).
#pragma once

namespace glintbake::runtime {

class TexelSource {
 public:
  virtual ~TexelSource() = default;
  virtual int width() const = 0;   // texels, >= 1
  virtual int height() const = 0;  // texels, >= 1
  // True when the grid repeats with its size; false when it continues with its edge texels.
  virtual bool repeats() const = 0;
  // s-plane normal (n_x, n_y) of texel (x, y), 0 <= x < width(), 0 <= y < height(): the tangent-space
  // normal's x and y (formats/SPEC.md section 9), finite. Called only while the evaluator is built.
  virtual void normal(int x, int y, float out[2]) const = 0;
};

}  // namespace glintbake::runtime
