// The process's heap policy. glibc serves an allocation above its mmap threshold (128 KiB at
// first) with fresh pages from the kernel and returns them when it is freed, so a matrix made and
// dropped every step (the EKF update's P H^T and innovation covariance, Eigen's packing buffers
// for a large product, a frame's image) pays a page fault per 4 KiB every time: about a third of
// a large team's step (docs/studies/speed.md). Keeping freed memory on the heap reuses it.
#pragma once

namespace wingman::io {

// Allocations up to 32 MiB (glibc's largest threshold) come from the heap, and up to 256 MiB
// freed at its top stays there. Call once, before the work starts; a no-op where the C library is
// not glibc.
void keep_freed_memory_on_the_heap();

}  // namespace wingman::io
