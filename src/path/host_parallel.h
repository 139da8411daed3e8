// The path family's host-only parallel loops: core/parallel.h's
// host_parallel_for (A* with its heaps, dynamic programming over std
// containers), named in this namespace for the family's callers.
#pragma once

#include "core/parallel.h"

namespace throng::path {

using throng::host_parallel_for;

}  // namespace throng::path
