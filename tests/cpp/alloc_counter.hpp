// SPDX-License-Identifier: BSD-3-Clause
// Counts every heap allocation of a C++ test executable (operator new and Eigen's aligned_malloc
// both end in malloc) in g_allocations, for the tests that a hot path allocates nothing. It
// defines malloc, calloc and realloc: include it in one source per executable (each test under
// tests/cpp is its own executable).
#pragma once

#include <atomic>
#include <cstdlib>

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
}
namespace {
std::atomic<long> g_allocations{0};
}  // namespace
extern "C" void* malloc(std::size_t n) {
  ++g_allocations;
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t n, std::size_t size) {
  ++g_allocations;
  return __libc_calloc(n, size);
}
extern "C" void* realloc(void* p, std::size_t n) {
  ++g_allocations;
  return __libc_realloc(p, n);
}
