/* Runs the native co-simulation loop (pendulum_fmu/fmu/_cs_loop.c, built as the wheel ships it) over
   an FMU binary with no Python around it, so that a platform without a Python here still runs
   both: the win64 DLLs under wine. It loads both libraries, instantiates the FMU and hands
   cs_loop_run the FMU's functions and a held torque for STEPS communication steps, twice, each
   time through the loop's restart (fmi2Reset, initialization with theta's start value): it
   writes theta at every point of the first run and fails unless the second gives the same bits.

   usage: cs_loop_harness LOOP_LIBRARY LIBRARY GUID STEPS STEP_SIZE 0 [TRAJECTORY]
   (after LOOP_LIBRARY, the command line of the bare masters, benchmarks/bare_master.h; the
   tolerance must be 0, undefined, as the loop's restart leaves it) */

#include <string.h>

#include "fmi2Functions.h"

#define MASTER_NAME "cs_loop_harness"
#define MASTER_TOKEN "GUID"
#include "bare_master.h"

/* What _native_loop.py checks too: the arguments below are those of this interface. */
#define CS_LOOP_INTERFACE 7

typedef int CsLoopInterface(void);
typedef int CsLoopRun(void *const *functions, fmi2Component component,
                      const fmi2ValueReference *start_references, size_t n_start, const double *start_values,
                      const double *tolerance, const fmi2ValueReference *input_references, size_t n_inputs,
                      const fmi2ValueReference *output_references, size_t n_outputs,
                      size_t n_steps, const double *time, const double *inputs,
                      const fmi2Integer *input_orders, const double *input_rates,
                      double *outputs, size_t *failed_step, int *failed_call);

/* The FMU's functions in the order of CsFunctions in _cs_loop.c, as _native_loop.py passes them. */
static const char *const LOOP_FUNCTIONS[] = {
    "fmi2Reset", "fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode",
    "fmi2SetReal", "fmi2SetRealInputDerivatives", "fmi2GetReal", "fmi2DoStep"};
#define N_LOOP_FUNCTIONS (sizeof LOOP_FUNCTIONS / sizeof LOOP_FUNCTIONS[0])

static void logger(fmi2ComponentEnvironment environment, fmi2String instance_name,
                   fmi2Status status, fmi2String category, fmi2String message, ...) {
    (void)environment;
    fprintf(stderr, "%s [%s] status %d: %s\n", instance_name, category, (int)status, message);
}

/* One case through the loop, restarted first with theta starting at 0. */
static void run_loop(CsLoopRun *run_case, void *const *functions, fmi2Component fmu, size_t steps,
                     const double *time, const double *torque, double *theta) {
    const fmi2ValueReference torque_vr = VR_TORQUE, theta_vr = VR_THETA;
    const double theta0 = 0.0;
    size_t failed_step = 0;
    int failed_call = -1;
    check(run_case(functions, fmu, &theta_vr, 1, &theta0, NULL, &torque_vr, 1, &theta_vr, 1, steps, time, torque,
                   NULL, NULL, theta, &failed_step, &failed_call),
          "cs_loop_run", (long)failed_step);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s LOOP_LIBRARY LIBRARY GUID STEPS STEP_SIZE 0 [TRAJECTORY]\n", argv[0]);
        return 2;
    }
    const Library loop = open_library(argv[1]);
    if (!loop) {
        fprintf(stderr, MASTER_NAME ": cannot load %s: %s\n", argv[1], library_error());
        return 2;
    }
    CsLoopInterface *const loop_interface = (CsLoopInterface *)symbol(loop, "cs_loop_interface");
    CsLoopRun *const run_case = (CsLoopRun *)symbol(loop, "cs_loop_run");
    if (loop_interface() != CS_LOOP_INTERFACE) {
        fprintf(stderr, MASTER_NAME ": %s has interface %d, this harness %d\n", argv[1], loop_interface(),
                CS_LOOP_INTERFACE);
        return 2;
    }

    const MasterRun run = start_master(argc - 1, argv + 1);
    if (run.tolerance != 0) {
        fprintf(stderr, MASTER_NAME ": the tolerance must be 0: this harness restarts with none defined\n");
        return 2;
    }
    LOOK_UP(run.library, fmi2Instantiate);
    LOOK_UP(run.library, fmi2FreeInstance);
    void *functions[N_LOOP_FUNCTIONS];
    for (size_t i = 0; i < N_LOOP_FUNCTIONS; i++) functions[i] = symbol(run.library, LOOP_FUNCTIONS[i]);

    const fmi2CallbackFunctions callbacks = {logger, NULL, NULL, NULL, NULL};
    fmi2Component fmu = fmi2Instantiate("harness", fmi2CoSimulation, run.token, "", &callbacks,
                                        fmi2False, fmi2False);
    if (!fmu) return 1;

    const size_t steps = (size_t)run.steps;
    double *const time = malloc((steps + 1) * sizeof *time);
    double *const torque = malloc(steps * sizeof *torque);
    double *const theta = malloc((steps + 1) * sizeof *theta);
    double *const restarted = malloc((steps + 1) * sizeof *restarted);
    if (!time || !torque || !theta || !restarted) {
        fprintf(stderr, MASTER_NAME ": out of memory for %lu steps\n", (unsigned long)steps);
        return 2;
    }
    /* Time as n*h, as the other masters, so both loops see the same points. */
    for (size_t k = 0; k <= steps; k++) time[k] = (double)k * run.step_size;
    for (size_t k = 0; k < steps; k++) torque[k] = TORQUE;

    run_loop(run_case, functions, fmu, steps, time, torque, theta);
    run_loop(run_case, functions, fmu, steps, time, torque, restarted);
    for (size_t k = 0; k <= steps; k++) record_theta(&run, theta[k]);
    close_trajectory(&run);
    if (memcmp(theta, restarted, (steps + 1) * sizeof *theta) != 0) {
        fprintf(stderr, MASTER_NAME ": the second run differs from the first\n");
        return 1;
    }

    fmi2FreeInstance(fmu);
    close_library(run.library);
    close_library(loop);
    free(time);
    free(torque);
    free(theta);
    free(restarted);
    return 0;
}
