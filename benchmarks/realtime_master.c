/* A bare FMI 2.0 master for the real-time sheet (docs/realtime.md): it steps the FMU through a
   square wave of torque and watches the steps in one of four ways.

   usage: realtime_master LIBRARY GUID MODE STEPS STEP_SIZE TORQUE HALF_PERIOD TOLERANCE [RECORD_FILE]

   The torque is +TORQUE for HALF_PERIOD steps, then -TORQUE for as many, and so on: HALF_PERIOD 1
   jumps at every step. TOLERANCE 0 leaves it undefined, so the FMU uses its default. RECORD_FILE,
   when given, switches the call record on (callRecordFile). Each step sets the torque, steps and
   reads theta, as the tutorial loop does. MODE is one of

   plain    steps and prints `theta` (the last) and `steps_done`, as every mode does at its end.
   counters counts what tests/c/heap_counter.c, preloaded, counts: heap calls (malloc and its
            kin, and the FMI memory callbacks, which the FMU must not use) from before the first
            fmi2DoStep to after the last, and per step the libm calls that mark the integrator's
            sub-steps (sincos: a Taylor step; sin: a DOPRI5 right-hand side). Prints them as
            `name value` lines.
   seccomp  forbids every system call but write on stdout and stderr and exit_group after the
            first fmi2GetReal and before the first step, with a filter the kernel enforces: a
            system call while stepping stops the master with status 3 and `system call N` on
            stderr (N its number; `write` when it was one, so a write to the record file).
   timing   prints `step_ns` lines, each the wall-clock nanoseconds of one
            fmi2SetReal + fmi2DoStep + fmi2GetReal (CLOCK_MONOTONIC), and of a discarded step's
            fmi2SetReal + fmi2DoStep.

   A discarded step ends the stepping: the master prints `discarded_at` (the step) and what its
   mode prints of the steps before and of that one. Exits 1 when a call fails otherwise, as
   bare_master.h's check does. */

#define _GNU_SOURCE /* RTLD_DEFAULT */
#include "fmi2Functions.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <stddef.h>
#include <sys/prctl.h>
#include <sys/syscall.h>

#define MASTER_NAME "realtime_master"
#define MASTER_TOKEN "GUID"
/* Its loading of the library and its checks, not its command line. */
#pragma GCC diagnostic ignored "-Wunused-function"
#include "bare_master.h"

/* callRecordFile's value reference in the FMI 2.0 model description. */
#define VR_CALL_RECORD_FILE 9

#if defined(__x86_64__)
#define AUDIT_ARCH_HERE AUDIT_ARCH_X86_64
#elif defined(__aarch64__)
#define AUDIT_ARCH_HERE AUDIT_ARCH_AARCH64
#else
#error "realtime_master knows the seccomp architecture of x86-64 and aarch64 only"
#endif

/* The FMI memory callbacks, counted: the FMU declares canNotUseMemoryManagementFunctions. */
static unsigned long callback_calls;
static void *allocate_memory(size_t n, size_t size) {
    callback_calls++;
    return calloc(n, size);
}
static void free_memory(void *pointer) {
    callback_calls++;
    free(pointer);
}

static void logger(fmi2ComponentEnvironment environment, fmi2String instance_name,
                   fmi2Status status, fmi2String category, fmi2String message, ...) {
    (void)environment;
    fprintf(stderr, "%s [%s] status %d: %s\n", instance_name, category, (int)status, message);
}

/* A counter of the preloaded tests/c/heap_counter.c; exits 2 when it is not preloaded. */
static const unsigned long *counter(const char *name) {
    const unsigned long *count = dlsym(RTLD_DEFAULT, name);
    if (!count) {
        fprintf(stderr, MASTER_NAME ": %s not found: preload heap_counter.so\n", name);
        exit(2);
    }
    return count;
}

/* Writes text on a descriptor with nothing but write(2), as a seccomp-bound master must. */
static void write_all(int descriptor, const char *text) {
    size_t left = strlen(text);
    while (left > 0) {
        const ssize_t written = write(descriptor, text, left);
        if (written <= 0) return;
        text += written;
        left -= (size_t)written;
    }
}

static void on_forbidden_call(int signal, siginfo_t *info, void *context) {
    (void)signal, (void)context;
    char line[64];
    const int number = info->si_syscall;
    snprintf(line, sizeof(line), "system call %d%s while stepping\n", number,
             number == __NR_write ? " (write)" : "");
    write_all(2, line);
    syscall(SYS_exit_group, 3);
}

/* From here on every system call but write on descriptors 1 and 2 and exit_group raises SIGSYS,
   which on_forbidden_call reports. Exits 4 where the kernel refuses the filter. */
static void forbid_system_calls(void) {
    struct sock_filter filter[] = {
        BPF_STMT(BPF_LD | BPF_W | BPF_ABS, offsetof(struct seccomp_data, arch)),
        BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, AUDIT_ARCH_HERE, 1, 0),
        BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_KILL_PROCESS),
        BPF_STMT(BPF_LD | BPF_W | BPF_ABS, offsetof(struct seccomp_data, nr)),
        BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, __NR_exit_group, 0, 1),
        BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_ALLOW),
        BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, __NR_write, 0, 3),
        BPF_STMT(BPF_LD | BPF_W | BPF_ABS, offsetof(struct seccomp_data, args[0])),
        BPF_JUMP(BPF_JMP | BPF_JGE | BPF_K, 3, 1, 0),
        BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_ALLOW),
        BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_TRAP),
    };
    const struct sock_fprog program = {sizeof(filter) / sizeof(filter[0]), filter};
    struct sigaction action;
    memset(&action, 0, sizeof(action));
    action.sa_sigaction = on_forbidden_call;
    action.sa_flags = SA_SIGINFO;
    if (sigaction(SIGSYS, &action, NULL) != 0 || prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0
        || prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, &program) != 0) {
        perror(MASTER_NAME ": seccomp unavailable");
        exit(4);
    }
}

static long nanoseconds(void) {
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return now.tv_sec * 1000000000L + now.tv_nsec;
}

typedef struct {
    const unsigned long *heap, *sincos, *sin;
    unsigned long heap_before, heap_after, callbacks_before, callbacks_after;
    unsigned long most_sincos, most_sin, total_sincos, total_sin;
} Counts;

static void print_counts(const Counts *counts) {
    printf("heap_calls_while_stepping %lu\ncallback_calls_while_stepping %lu\n"
           "most_sincos_per_step %lu\nmost_sin_per_step %lu\ntotal_sincos %lu\ntotal_sin %lu\n"
           "heap_calls_before_stepping %lu\ncallback_calls %lu\n",
           counts->heap_after - counts->heap_before,
           counts->callbacks_after - counts->callbacks_before,
           counts->most_sincos, counts->most_sin, counts->total_sincos, counts->total_sin,
           counts->heap_before, counts->callbacks_after);
}

typedef struct {
    const char *library, *guid, *record_file; /* record_file NULL: the record stays off */
    int counting, sealed, timing;
    long steps, half_period;
    double step_size, amplitude, tolerance;
} Run;

/* Exits with status 2, as a usage error, when the command line is unusable. */
static Run parse_run(int argc, char **argv) {
    if (argc < 9 || argc > 10) {
        fprintf(stderr, "usage: %s LIBRARY GUID MODE STEPS STEP_SIZE TORQUE HALF_PERIOD TOLERANCE "
                        "[RECORD_FILE]\n", argv[0]);
        exit(2);
    }
    const char *mode = argv[3];
    const Run run = {argv[1], argv[2], argc == 10 ? argv[9] : NULL,
                     !strcmp(mode, "counters"), !strcmp(mode, "seccomp"), !strcmp(mode, "timing"),
                     atol(argv[4]), atol(argv[7]), atof(argv[5]), atof(argv[6]), atof(argv[8])};
    if (!(run.counting || run.sealed || run.timing || !strcmp(mode, "plain")) || run.steps < 1
        || run.half_period < 1) {
        fprintf(stderr, MASTER_NAME ": MODE is plain, counters, seccomp or timing; STEPS and "
                        "HALF_PERIOD at least 1\n");
        exit(2);
    }
    return run;
}

/* An instance out of initialization, with the record on where the run names a file. */
static fmi2Component start_fmu(Library library, const Run *run) {
    LOOK_UP(library, fmi2Instantiate);
    LOOK_UP(library, fmi2SetupExperiment);
    LOOK_UP(library, fmi2EnterInitializationMode);
    LOOK_UP(library, fmi2ExitInitializationMode);
    LOOK_UP(library, fmi2SetString);
    static const fmi2CallbackFunctions callbacks = {logger, allocate_memory, free_memory, NULL,
                                                    NULL};
    fmi2Component fmu = fmi2Instantiate("master", fmi2CoSimulation, run->guid, "", &callbacks,
                                        fmi2False, fmi2False);
    if (!fmu) exit(1);
    if (run->record_file) {
        const fmi2ValueReference reference = VR_CALL_RECORD_FILE;
        check(fmi2SetString(fmu, &reference, 1, &run->record_file), "fmi2SetString", 0);
    }
    check(fmi2SetupExperiment(fmu, run->tolerance > 0, run->tolerance, 0.0, fmi2False, 0.0),
          "fmi2SetupExperiment", 0);
    check(fmi2EnterInitializationMode(fmu), "fmi2EnterInitializationMode", 0);
    check(fmi2ExitInitializationMode(fmu), "fmi2ExitInitializationMode", 0);
    return fmu;
}

int main(int argc, char **argv) {
    const Run run = parse_run(argc, argv);
    const int counting = run.counting, timing = run.timing;
    const long steps = run.steps;
    long *step_ns = timing ? malloc(sizeof(long) * (size_t)steps) : NULL;
    Counts counts = {0};
    if (counting) {
        counts.heap = counter("heap_counter_calls");
        counts.sincos = counter("heap_counter_sincos");
        counts.sin = counter("heap_counter_sin");
    }
    const Library library = open_library(run.library);
    if (!library) {
        fprintf(stderr, MASTER_NAME ": cannot load %s: %s\n", run.library, library_error());
        return 2;
    }
    LOOK_UP(library, fmi2SetReal);
    LOOK_UP(library, fmi2GetReal);
    LOOK_UP(library, fmi2DoStep);
    fmi2Component fmu = start_fmu(library, &run);

    const fmi2ValueReference torque_vr = VR_TORQUE, theta_vr = VR_THETA;
    double theta;
    check(fmi2GetReal(fmu, &theta_vr, 1, &theta), "fmi2GetReal", 0);
    if (run.sealed) forbid_system_calls();
    if (counting) counts.heap_before = *counts.heap, counts.callbacks_before = callback_calls;
    long k, discarded_at = -1;
    for (k = 0; k < steps; k++) {
        const double torque = (k / run.half_period) % 2 ? -run.amplitude : run.amplitude;
        const long start = timing ? nanoseconds() : 0;
        const unsigned long sincos_before = counting ? *counts.sincos : 0,
                            sin_before = counting ? *counts.sin : 0;
        check(fmi2SetReal(fmu, &torque_vr, 1, &torque), "fmi2SetReal", k);
        /* Time as n*h, not a running sum, so it never drifts from where the FMU stands. */
        const fmi2Status status = fmi2DoStep(fmu, k * run.step_size, run.step_size, fmi2True);
        if (counting) {
            const unsigned long sincos = *counts.sincos - sincos_before, sin = *counts.sin - sin_before;
            counts.most_sincos = sincos > counts.most_sincos ? sincos : counts.most_sincos;
            counts.most_sin = sin > counts.most_sin ? sin : counts.most_sin;
            counts.total_sincos += sincos;
            counts.total_sin += sin;
        }
        if (status == fmi2Discard) {
            /* Timed too: a step spends most on its way to a discard. */
            if (timing) step_ns[k] = nanoseconds() - start;
            discarded_at = k;
            break;
        }
        check(status, "fmi2DoStep", k);
        check(fmi2GetReal(fmu, &theta_vr, 1, &theta), "fmi2GetReal", k);
        if (timing) step_ns[k] = nanoseconds() - start;
    }
    if (counting) {
        /* Before anything is printed: stdout's buffer is allocated at its first use. */
        counts.heap_after = *counts.heap, counts.callbacks_after = callback_calls;
        print_counts(&counts);
    }
    if (discarded_at >= 0) printf("discarded_at %ld\n", discarded_at);
    if (timing)
        for (long i = 0; i < k + (discarded_at >= 0); i++) printf("step_ns %ld\n", step_ns[i]);
    char result[96];
    snprintf(result, sizeof(result), "theta %.17g\nsteps_done %ld\n", theta, k);
    fflush(stdout);
    write_all(1, result);
    /* No fmi2Terminate or fmi2FreeInstance: they close the record file, a system call the seccomp
       filter would stop; the process ends here anyway. */
    _exit(0);
}
