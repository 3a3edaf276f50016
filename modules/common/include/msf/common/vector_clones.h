// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// MSF_VECTOR_CLONES before a function whose loops vectorize: GCC compiles it twice, for
// x86-64's baseline (SSE2) and for AVX2 (twice the lanes), and the loader picks the copy the
// CPU runs. No FMA in the AVX2 copy, so both give the same floats. Elsewhere it is nothing.
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
#define MSF_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define MSF_VECTOR_CLONES
#endif
