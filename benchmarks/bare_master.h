/* What the bare C masters share whatever their FMI version (step_master.c for FMI 2.0,
   fmi3_step_master.c for FMI 3.0): the command line, loading the FMU's library with dlopen or, on
   Windows, LoadLibrary, and leaving with a message when something fails. Only the FMI calls
   differ between the masters, so a run of each checks the same numbers.

   usage: MASTER LIBRARY TOKEN STEPS STEP_SIZE TOLERANCE [TRAJECTORY]
   TOKEN is the FMI 2.0 guid or the FMI 3.0 instantiationToken; TOLERANCE 0 leaves it undefined,
   so the FMU uses its default; TRAJECTORY, when given, receives theta at every step.

   Define MASTER_NAME (the prefix of its messages) and MASTER_TOKEN (what usage calls TOKEN)
   before including this. */

#ifndef BARE_MASTER_H
#define BARE_MASTER_H

#include <stdio.h>
#include <stdlib.h>

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

/* The interface every FMU benchmarked here shares (see benchmarks/null_fmu/), the same value
   references in both FMI versions. */
#define VR_TORQUE 0
#define VR_THETA 1
#define TORQUE 20.0

typedef struct {
    Library library;
    const char *token;
    long steps;
    double step_size;
    double tolerance;
    FILE *trajectory;            /* NULL when no TRAJECTORY was given */
    const char *trajectory_path;
} MasterRun;

/* Exits with status 2, as a usage error, when the command line or the library is unusable. */
static MasterRun start_master(int argc, char **argv) {
    if (argc < 6 || argc > 7) {
        fprintf(stderr, "usage: %s LIBRARY " MASTER_TOKEN " STEPS STEP_SIZE TOLERANCE [TRAJECTORY]\n",
                argv[0]);
        exit(2);
    }
    MasterRun run = {NULL, argv[2], atol(argv[3]), atof(argv[4]), atof(argv[5]), NULL, NULL};
    if (argc == 7) {
        run.trajectory_path = argv[6];
        if (!(run.trajectory = fopen(run.trajectory_path, "w"))) {
            perror(run.trajectory_path);
            exit(2);
        }
    }
    if (!(run.library = open_library(argv[1]))) {
        fprintf(stderr, MASTER_NAME ": cannot load %s: %s\n", argv[1], library_error());
        exit(2);
    }
    return run;
}

static void *symbol(Library library, const char *name) {
    void *pointer = find_symbol(library, name);
    if (!pointer) {
        fprintf(stderr, MASTER_NAME ": %s not found: %s\n", name, library_error());
        exit(2);
    }
    return pointer;
}

/* Declares a pointer named after an FMI function (fmi2DoStep, fmi3DoStep...) and looks it up, so
   a call reads as the standard names it. The pointer shadows the FMI header's declaration of the
   function on purpose: a master never links against an FMU, it only loads one. */
#define LOOK_UP(library, function) function##TYPE *const function = symbol(library, #function)

/* fmi2OK and fmi3OK are both 0, so one check serves either version's status. */
static void check(int status, const char *call, long step) {
    if (status != 0) {
        fprintf(stderr, MASTER_NAME ": %s returned %d at step %ld\n", call, status, step);
        exit(1);
    }
}

static void record_theta(const MasterRun *run, double theta) {
    if (run->trajectory) fprintf(run->trajectory, "%.17g\n", theta);
}

static void close_trajectory(const MasterRun *run) {
    if (run->trajectory && fclose(run->trajectory) != 0) {
        perror(run->trajectory_path);
        exit(2);
    }
}

#endif
