/* Whether two symbol versions of the C library's pow give the same bits: the zig builds for an
   old glibc (cmake/linux.cmake) bind pow@GLIBC_2.2.5 on x86_64 and pow@GLIBC_2.17 on aarch64,
   gcc's on Debian 12 pow@GLIBC_2.29. It takes both from this machine's libm with dlvsym and
   calls them on COUNT inputs: every other one pow(error, -0.2) as the integrator's step-size
   controller computes it (fmu_src/src/dopri5.c), error from 1e-30 to 1e3; the others x of any
   mantissa from 2^-60 to 2^60 to a power in [-16, 16], whose results are finite: from a fixed
   xorshift sequence.

   usage: pow_versions OLD_VERSION COUNT
   prints: "<differing> of <COUNT> differ" (and the first few that do); exit status 0 */

#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef double Pow(double, double);

static uint64_t state = 88172645463325252u;

static uint64_t random_bits(void) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
}

static double uniform(void) { /* in [0, 1) */
    return (double)(random_bits() >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: pow_versions OLD_VERSION COUNT\n");
        return 2;
    }
    void *libm = dlopen("libm.so.6", RTLD_NOW);
    Pow *old = libm ? (Pow *)dlvsym(libm, "pow", argv[1]) : NULL;
    Pow *new = libm ? (Pow *)dlvsym(libm, "pow", "GLIBC_2.29") : NULL;
    if (!old || !new) {
        fprintf(stderr, "pow_versions: no pow@%s or pow@GLIBC_2.29 in libm.so.6\n", argv[1]);
        return 2;
    }
    const long count = atol(argv[2]);
    long differing = 0;
    for (long i = 0; i < count; i++) {
        double x, y;
        if (i % 2 == 0) {
            x = new(10.0, -30.0 + 33.0 * uniform());
            y = -0.2;
        } else {
            const uint64_t exponent = 1023 - 60 + random_bits() % 120;
            const uint64_t bits = exponent << 52 | random_bits() >> 12;
            memcpy(&x, &bits, sizeof x);
            y = -16.0 + 32.0 * uniform();
        }
        const double a = old(x, y), b = new(x, y);
        if (memcmp(&a, &b, sizeof a) != 0 && ++differing <= 5)
            printf("pow(%a, %a): %a, %a\n", x, y, a, b);
    }
    printf("%ld of %ld differ\n", differing, count);
    return 0;
}
