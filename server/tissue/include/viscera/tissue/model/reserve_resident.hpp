#pragma once  // SPDX-License-Identifier: Apache-2.0
// Room reserved in a vector and written once, so that its pages are resident: a vector that later
// grows into it takes no page faults. A cut of the 12k liver grows the model's lanes, the memory
// variables and the mesh into fresh pages at nearly every sweep, and in a virtual machine each
// first touch of a page costs microseconds (docs/CUTTING.md, "Timing").
#include <cstddef>
#include <vector>

namespace viscera::tissue {

template <class T>
void reserve_resident(std::vector<T>& v, std::size_t n) {
  if (n <= v.size()) return;
  const std::size_t size = v.size();
  v.reserve(n);
  v.resize(n);  // value-initialised: every page written
  v.resize(size);  // the capacity, and its pages, stay
}

}  // namespace viscera::tissue
