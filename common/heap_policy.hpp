#pragma once
// How the stentsim executable asks glibc's malloc to treat large blocks.
//
// By default glibc serves every block above its mmap threshold (at most
// 32 MB) with a fresh mmap and gives it back with munmap on free. A sparse
// LU factorization (UMFPACK's numeric object: 200 MB on the free expansion
// with its contact coupling, rebuilt dozens of times per run) then pays, each
// time, for the kernel's page faults and the zeroing of every page. Serving
// all blocks from the heap and never trimming it lets the next factorization
// reuse the pages the last one freed: on the free expansion's solve (two
// assembly threads, one rank, runs alternated) 55–58 s became 44–45 s with
// the same settings made through glibc's environment variables and 46 s with
// this function (one run); the peak resident memory 512–521 MB became
// 529–544 MB. What a process frees stays resident until it exits: each stage
// runs in a child of its own (pipeline/stage_process.cpp), so that is the
// stage's own peak.
namespace stentsim::heap {

/// Heap for every block, no trimming (mallopt M_MMAP_MAX = 0, M_TRIM_THRESHOLD
/// = -1), unless the environment already sets glibc's malloc options
/// (MALLOC_MMAP_MAX_, MALLOC_TRIM_THRESHOLD_, MALLOC_MMAP_THRESHOLD_ or a
/// glibc.malloc tunable in GLIBC_TUNABLES): then the user's choice stands. Returns true when applied.
/// glibc falls back to mmap where the heap cannot grow, and thread arenas to
/// mmap for blocks larger than their heaps.
bool keep_large_blocks();

}  // namespace stentsim::heap
