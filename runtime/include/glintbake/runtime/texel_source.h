// SPDX-License-Identifier: Apache-2.0
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

// A texel source over a caller-owned row-major array holding `stride` floats per texel, (n_x, n_y)
// first (stride 2: a flakes section's normals; stride 3: x, y, z normals). The array must outlive
// the source; nothing is copied.
class InterleavedTexels final : public TexelSource {
 public:
  InterleavedTexels(int width, int height, bool repeats, const float* data, int stride)
      : width_(width), height_(height), repeats_(repeats), data_(data), stride_(stride) {}
  int width() const override { return width_; }
  int height() const override { return height_; }
  bool repeats() const override { return repeats_; }
  void normal(int x, int y, float out[2]) const override {
    const float* n = data_ + (static_cast<long long>(y) * width_ + x) * stride_;
    out[0] = n[0];
    out[1] = n[1];
  }

 private:
  int width_, height_;
  bool repeats_;
  const float* data_;
  int stride_;
};

}  // namespace glintbake::runtime
