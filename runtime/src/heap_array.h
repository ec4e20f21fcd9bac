// SPDX-License-Identifier: Apache-2.0
// Owning heap array of the runtime: allocation failure is reported, never thrown, and storage is
// aligned to a cache line (a rank-16 float row of a CP factor then spans exactly one line instead
// of straddling two). Internal to the runtime.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>

namespace glintbake::runtime {

template <typename T>
struct Array {
  static constexpr std::align_val_t kAlignment{64};

  T* data = nullptr;
  size_t size = 0;
  Array() = default;
  Array(const Array&) = delete;
  Array& operator=(const Array&) = delete;
  ~Array() { release(); }

  // Default-initialised elements (plain numbers are left unset, as by new T[n]).
  bool allocate(size_t n) {
    release();
    if (n > SIZE_MAX / sizeof(T)) return false;
    void* raw = ::operator new((n > 0 ? n : 1) * sizeof(T), kAlignment, std::nothrow);
    if (!raw) return false;
    data = static_cast<T*>(raw);
    for (size_t i = 0; i < n; ++i) new (data + i) T;
    size = n;
    return true;
  }

  void release() {
    if (!data) return;
    for (size_t i = 0; i < size; ++i) data[i].~T();
    ::operator delete(data, kAlignment);
    data = nullptr;
    size = 0;
  }
};

}  // namespace glintbake::runtime
