// SPDX-License-Identifier: Apache-2.0
// The on-disk records of tensor-ndf assets, as the runtime names them. The records and their
// checks live in the container library (glintbake/format/kinds/tensor_ndf.h, formats/SPEC.md
// section 10.4); this header keeps the runtime's names.
#pragma once

#include <glintbake/format/kinds/tensor_ndf.h>

namespace glintbake::runtime {

using format::kTensorBlankGroup;
using format::kTensorFlagNonNegative;
using format::TensorGroupHeader;
using format::TensorIndexEntry;
using format::TensorInfoRecord;

}  // namespace glintbake::runtime
