/* ===== >>impl : implementation ===================================================================== */

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#if defined(FSDEM_MALLOC) && defined(FSDEM_REALLOC) && defined(FSDEM_FREE)
/* user-supplied */
#elif !defined(FSDEM_MALLOC) && !defined(FSDEM_REALLOC) && !defined(FSDEM_FREE)
#include <stdlib.h>
#define FSDEM_MALLOC(sz) malloc(sz)
#define FSDEM_REALLOC(p, sz) realloc(p, sz)
#define FSDEM_FREE(p) free(p)
#else
#error "fsdem.h: define all of FSDEM_MALLOC, FSDEM_REALLOC and FSDEM_FREE, or none"
#endif

#ifndef FSDEM_ASSERT
#include <assert.h>
#define FSDEM_ASSERT(c) assert(c)
#endif

/* Results must not depend on the compiler fusing a * b + c into one rounding (it changes the last
   bits, and a chaotic run then diverges), so the implementation forbids the contraction where the
   compiler honours the standard pragma (clang). GCC contracts only in its GNU modes: build with
   -std=c99 (or -ffp-contract=off) for results that are the same bit for bit across compilers. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
