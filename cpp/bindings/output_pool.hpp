// SPDX-License-Identifier: BSD-3-Clause
#pragma once

#include <pybind11/numpy.h>

#include <cstdlib>
#include <new>
#include <vector>

namespace armdyn::py_helpers {

namespace py = pybind11;

// The large outputs of the batch calls (rows.hpp batch(), the derivatives' matrices), their
// buffers kept for the next call when their arrays are freed: a batch on many rows writes
// megabytes of fresh memory, and the allocator hands large blocks back to the system when they
// are freed (and trims the heap's top), so that each call paid the kernel's zero-filling page
// faults again (on solo12 at 1000 rows, a third of a derivatives call). Only this module's own
// arrays of at least kMinBytes; at most kMaxHeld bytes in kMaxBlocks blocks are kept (the rest
// freed); a buffer is reused for a request between half its size and its size. Touched only
// with the GIL held (array creation and destruction). Like numpy.empty, the contents are not
// initialised: the callers write every entry.
class OutputPool {
 public:
  static constexpr size_t kMinBytes = size_t{1} << 20, kMaxHeld = size_t{64} << 20;
  static constexpr size_t kMaxBlocks = 6;

  static OutputPool& get() {
    static auto* pool = new OutputPool();  // never destroyed: arrays may outlive exit
    return *pool;
  }

  /// a C-contiguous float64 array of this shape, its buffer from the pool when large
  py::array_t<double> array(const std::vector<py::ssize_t>& shape) {
    size_t bytes = sizeof(double);
    for (py::ssize_t e : shape) bytes *= static_cast<size_t>(e);
    if (bytes < kMinBytes) return py::array_t<double>(shape);
    Block* b = take(bytes);
    if (b == nullptr) {
      b = new Block{bytes, static_cast<double*>(std::malloc(bytes))};
      if (b->data == nullptr) {
        delete b;
        throw std::bad_alloc();
      }
    }
    py::capsule owner(b, [](void* p) { get().give(static_cast<Block*>(p)); });
    return py::array_t<double>(shape, b->data, owner);
  }

 private:
  struct Block {
    size_t bytes;
    double* data;
  };
  std::vector<Block*> free_;
  size_t held_ = 0;

  Block* take(size_t bytes) {
    for (size_t i = 0; i < free_.size(); ++i) {
      Block* b = free_[i];
      if (b->bytes >= bytes && b->bytes / 2 <= bytes) {
        free_.erase(free_.begin() + static_cast<long>(i));
        held_ -= b->bytes;
        return b;
      }
    }
    return nullptr;
  }

  void give(Block* b) {
    while (!free_.empty() && (free_.size() >= kMaxBlocks || held_ + b->bytes > kMaxHeld)) {
      held_ -= free_.front()->bytes;  // the oldest first
      std::free(free_.front()->data);
      delete free_.front();
      free_.erase(free_.begin());
    }
    if (b->bytes > kMaxHeld) {
      std::free(b->data);
      delete b;
      return;
    }
    free_.push_back(b);
    held_ += b->bytes;
  }
};

}  // namespace armdyn::py_helpers
