/* A bare FMI 2.0 co-simulation master, so that callgrind sees the FMU's instructions and almost
   nothing else: no interpreter, no wrapper. It runs the tutorial loop (set the torque, step, read
   theta) and can write theta at every step, so a run can be checked. It builds for Linux and,
   cross-compiled, for Windows, where the tests run it under wine against the DLL.

   usage: step_master LIBRARY GUID STEPS STEP_SIZE TOLERANCE [TORQUE]
   TOLERANCE 0 leaves it undefined, so the FMU uses its default. */

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "fmi2Functions.h"

#ifdef _WIN32
#include <windows.h>
typedef HMODULE Library;
static Library open_library(const char *path) { return LoadLibraryA(path); }
static void *find_symbol(Library library, const char *name) {
    return (void *)(INT_PTR)GetProcAddress(library, name);
}
static void close_library(Library library) { FreeLibrary(library); }
static const char *library_error(void) { return "LoadLibrary/GetProcAddress failed"; }
#else
#include <dlfcn.h>
typedef void *Library;
static Library open_library(const char *path) { return dlopen(path, RTLD_NOW | RTLD_LOCAL); }
static void *find_symbol(Library library, const char *name) { return dlsym(library, name); }
static void close_library(Library library) { dlclose(library); }
static const char *library_error(void) { return dlerror(); }
#endif

/* The interface every FMU benchmarked here shares (see benchmarks/null_fmu/). */
#define VR_TORQUE 0
#define VR_THETA 1
#define TORQUE 20.0

static void logger(fmi2ComponentEnvironment environment, fmi2String instance_name,
                   fmi2Status status, fmi2String category, fmi2String message, ...) {
    (void)environment;
    fprintf(stderr, "%s [%s] status %d: %s\n", instance_name, category, (int)status, message);
}

static void *symbol(Library library, const char *name) {
    void *pointer = find_symbol(library, name);
    if (!pointer) {
        fprintf(stderr, "step_master: %s not found: %s\n", name, library_error());
        exit(2);
    }
    return pointer;
}

static void check(fmi2Status status, const char *call, long step) {
    if (status != fmi2OK) {
        fprintf(stderr, "step_master: %s returned %d at step %ld\n", call, (int)status, step);
        exit(1);
    }
}

int main(int argc, char **argv) {
    if (argc < 6 || argc > 7) {
        fprintf(stderr, "usage: %s LIBRARY GUID STEPS STEP_SIZE TOLERANCE [TRAJECTORY]\n", argv[0]);
        return 2;
    }
    const long steps = atol(argv[3]);
    const double step_size = atof(argv[4]);
    const double tolerance = atof(argv[5]);
    FILE *trajectory = NULL;
    if (argc == 7 && !(trajectory = fopen(argv[6], "w"))) {
        perror(argv[6]);
        return 2;
    }

    Library library = open_library(argv[1]);
    if (!library) {
        fprintf(stderr, "step_master: cannot load %s: %s\n", argv[1], library_error());
        return 2;
    }
    fmi2InstantiateTYPE *instantiate = symbol(library, "fmi2Instantiate");
    fmi2SetupExperimentTYPE *setup_experiment = symbol(library, "fmi2SetupExperiment");
    fmi2EnterInitializationModeTYPE *enter_initialization =
        symbol(library, "fmi2EnterInitializationMode");
    fmi2ExitInitializationModeTYPE *exit_initialization = symbol(library, "fmi2ExitInitializationMode");
    fmi2SetRealTYPE *set_real = symbol(library, "fmi2SetReal");
    fmi2GetRealTYPE *get_real = symbol(library, "fmi2GetReal");
    fmi2DoStepTYPE *do_step = symbol(library, "fmi2DoStep");
    fmi2TerminateTYPE *terminate = symbol(library, "fmi2Terminate");
    fmi2FreeInstanceTYPE *free_instance = symbol(library, "fmi2FreeInstance");

    const fmi2CallbackFunctions callbacks = {logger, NULL, NULL, NULL, NULL};
    fmi2Component fmu = instantiate("master", fmi2CoSimulation, argv[2], "", &callbacks,
                                    fmi2False, fmi2False);
    if (!fmu) return 1;
    check(setup_experiment(fmu, tolerance > 0, tolerance, 0.0, fmi2False, 0.0),
          "fmi2SetupExperiment", 0);
    check(enter_initialization(fmu), "fmi2EnterInitializationMode", 0);
    check(exit_initialization(fmu), "fmi2ExitInitializationMode", 0);

    const fmi2ValueReference torque_vr = VR_TORQUE, theta_vr = VR_THETA;
    const double torque = TORQUE;
    double theta;
    check(get_real(fmu, &theta_vr, 1, &theta), "fmi2GetReal", 0);
    if (trajectory) fprintf(trajectory, "%.17g\n", theta);
    for (long k = 0; k < steps; k++) {
        /* Time as n*h, not a running sum, so it never drifts from where the FMU stands. */
        const double time = k * step_size;
        check(set_real(fmu, &torque_vr, 1, &torque), "fmi2SetReal", k);
        check(do_step(fmu, time, step_size, fmi2True), "fmi2DoStep", k);
        check(get_real(fmu, &theta_vr, 1, &theta), "fmi2GetReal", k);
        if (trajectory) fprintf(trajectory, "%.17g\n", theta);
    }
    if (trajectory && fclose(trajectory) != 0) {
        perror(argv[6]);
        return 2;
    }

    terminate(fmu);
    free_instance(fmu);
    close_library(library);
    return 0;
}
