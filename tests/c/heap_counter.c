/* Preloaded (LD_PRELOAD) into benchmarks/realtime_master.c, it counts what a process asks of the
   heap and of libm, and exports the counts for the master to read between steps:

   heap_counter_calls   calls of malloc, calloc, realloc, reallocarray, free, posix_memalign,
                        aligned_alloc, memalign, valloc and pvalloc, from anywhere in the process
   heap_counter_sincos  calls of sincos: the FMU's Taylor series calls it once per sub-step
   heap_counter_sin     calls of sin: DOPRI5's right-hand side calls it once per evaluation

   The counts come from the library calls themselves, so they share nothing with the
   integrator's own step counter. Each function hands on to glibc's (__libc_malloc and its kin,
   or libm's, found in a constructor, so that no lookup allocates while the master counts). */

#include <dlfcn.h>
#include <stddef.h>
#include <stdlib.h>
#include <unistd.h>

/* What the master reads (dlsym); volatile, so that no increment is merged or left out. */
volatile unsigned long heap_counter_calls, heap_counter_sincos, heap_counter_sin;

extern void *__libc_malloc(size_t size);
extern void *__libc_calloc(size_t n, size_t size);
extern void *__libc_realloc(void *pointer, size_t size);
extern void __libc_free(void *pointer);
extern void *__libc_memalign(size_t alignment, size_t size);

static void (*libm_sincos)(double, double *, double *);
static double (*libm_sin)(double);

__attribute__((constructor)) static void find_libm(void) {
    /* libm by name: the master itself does not link it, the FMU it loads later does. */
    void *libm = dlopen("libm.so.6", RTLD_NOW | RTLD_LOCAL);
    if (libm) {
        libm_sincos = (void (*)(double, double *, double *))dlsym(libm, "sincos");
        libm_sin = (double (*)(double))dlsym(libm, "sin");
    }
    if (!libm_sincos || !libm_sin) abort();
}

void *malloc(size_t size) {
    heap_counter_calls++;
    return __libc_malloc(size);
}

void *calloc(size_t n, size_t size) {
    heap_counter_calls++;
    return __libc_calloc(n, size);
}

void *realloc(void *pointer, size_t size) {
    heap_counter_calls++;
    return __libc_realloc(pointer, size);
}

void *reallocarray(void *pointer, size_t n, size_t size) {
    heap_counter_calls++;
    if (size && n > (size_t)-1 / size) return NULL;
    return __libc_realloc(pointer, n * size);
}

void free(void *pointer) {
    heap_counter_calls++;
    __libc_free(pointer);
}

void *memalign(size_t alignment, size_t size) {
    heap_counter_calls++;
    return __libc_memalign(alignment, size);
}

void *aligned_alloc(size_t alignment, size_t size) {
    heap_counter_calls++;
    return __libc_memalign(alignment, size);
}

int posix_memalign(void **pointer, size_t alignment, size_t size) {
    heap_counter_calls++;
    void *memory = __libc_memalign(alignment, size);
    if (!memory && size) return 12; /* ENOMEM */
    *pointer = memory;
    return 0;
}

void *valloc(size_t size) {
    heap_counter_calls++;
    return __libc_memalign((size_t)sysconf(_SC_PAGESIZE), size);
}

void *pvalloc(size_t size) {
    heap_counter_calls++;
    const size_t page = (size_t)sysconf(_SC_PAGESIZE);
    return __libc_memalign(page, (size + page - 1) / page * page);
}

void sincos(double x, double *sine, double *cosine) {
    heap_counter_sincos++;
    libm_sincos(x, sine, cosine);
}

double sin(double x) {
    heap_counter_sin++;
    return libm_sin(x);
}
