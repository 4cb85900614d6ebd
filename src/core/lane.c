/* ---- >>core_lane : short vectors for batched kernels ---- */

/* An fsdem__lane holds FSDEM__LANES reals that one instruction processes, where the compiler has GNU
   vector extensions (gcc, clang): 16 bytes (SSE2, NEON), 32 with AVX, 64 with AVX-512, as the target
   flags allow. Elsewhere, or with FSDEM_NO_SIMD, it is a single real. A kernel written with + - * /
   on lanes and the functions below compiles to either, so its arithmetic exists once. Comparisons
   give an fsdem__mask (all bits set or clear per lane) for fsdem__lane_select; combine masks with
   & and |. Kernels keep every lane finite (padding repeats a real entry, divisors are guarded), so
   they raise no floating-point exceptions. */
#if (defined(__GNUC__) || defined(__clang__)) && !defined(FSDEM_NO_SIMD)
#if defined(__AVX512F__)
#define FSDEM__LANE_BYTES 64
#elif defined(__AVX__)
#define FSDEM__LANE_BYTES 32
#else
#define FSDEM__LANE_BYTES 16
#endif
#define FSDEM__LANES ((int)(FSDEM__LANE_BYTES / sizeof(fsdem_real)))
typedef fsdem_real fsdem__lane __attribute__((vector_size(FSDEM__LANE_BYTES)));
#ifdef FSDEM_USE_FLOAT
typedef int fsdem__mask __attribute__((vector_size(FSDEM__LANE_BYTES)));
#else
typedef long long fsdem__mask __attribute__((vector_size(FSDEM__LANE_BYTES)));
#endif
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#elif defined(__aarch64__)
#include <arm_neon.h>
#endif

FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_select(fsdem__mask m, fsdem__lane a, fsdem__lane b) {
    return (fsdem__lane)(((fsdem__mask)a & m) | ((fsdem__mask)b & ~m));
}

/* libm's sqrt sets errno and is called lane by lane; the instructions are not */
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_sqrt(fsdem__lane a) {
#if defined(FSDEM_USE_FLOAT) && FSDEM__LANE_BYTES == 64 /* (the zero-masked forms: g++ 12 warns inside the plain ones) */
    return (fsdem__lane)_mm512_maskz_sqrt_ps((__mmask16)0xFFFF, (__m512)a);
#elif FSDEM__LANE_BYTES == 64
    return (fsdem__lane)_mm512_maskz_sqrt_pd((__mmask8)0xFF, (__m512d)a);
#elif defined(FSDEM_USE_FLOAT) && FSDEM__LANE_BYTES == 32
    return (fsdem__lane)_mm256_sqrt_ps((__m256)a);
#elif FSDEM__LANE_BYTES == 32
    return (fsdem__lane)_mm256_sqrt_pd((__m256d)a);
#elif defined(FSDEM_USE_FLOAT) && defined(__SSE__)
    return (fsdem__lane)_mm_sqrt_ps((__m128)a);
#elif defined(__SSE2__)
    return (fsdem__lane)_mm_sqrt_pd((__m128d)a);
#elif defined(FSDEM_USE_FLOAT) && defined(__aarch64__)
    return (fsdem__lane)vsqrtq_f32((float32x4_t)a);
#elif defined(__aarch64__)
    return (fsdem__lane)vsqrtq_f64((float64x2_t)a);
#else
    int l;
    for (l = 0; l < FSDEM__LANES; ++l) a[l] = (fsdem_real)sqrt(a[l]);
    return a;
#endif
}
#else
#define FSDEM__LANES 1
typedef fsdem_real fsdem__lane;
typedef int fsdem__mask; /* 0 or 1 */

FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_select(fsdem__mask m, fsdem__lane a, fsdem__lane b) { return m ? a : b; }
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_sqrt(fsdem__lane a) { return (fsdem_real)sqrt(a); }
#endif

/* Lanes from and to reals at p (no alignment needed). */
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_load(const fsdem_real *p) {
    fsdem__lane a;
    memcpy(&a, p, sizeof a);
    return a;
}
FSDEM__FORCE_INLINE void fsdem__lane_store(fsdem_real *p, fsdem__lane a) { memcpy(p, &a, sizeof a); }
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_max(fsdem__lane a, fsdem__lane b) { return fsdem__lane_select(a > b, a, b); }
FSDEM__FORCE_INLINE fsdem__lane fsdem__lane_set(fsdem_real s) {
    fsdem_real v[FSDEM__LANES];
    int l;
    for (l = 0; l < FSDEM__LANES; ++l) v[l] = s;
    return fsdem__lane_load(v);
}
