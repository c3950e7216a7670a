/* Runs the native co-simulation loop (pendulum_fmu/fmu/_cs_loop.c, built as the wheel ships it) over
   an FMU binary with no Python around it, so that a platform without a Python here still runs
   both: the win64 DLLs under wine. It loads both libraries, instantiates the FMU and hands
   cs_loop_run the FMU's functions and a held torque for STEPS communication steps, twice, each
   time through the loop's restart (fmi2Reset, initialization with theta's start value): it
   writes theta at every point of the first run and fails unless the second gives the same bits.
   Then it steps BATCH instances of the FMU together through the loop's batch (cs_loop_batch_advance,
   _cs_batch.c) on a pool of BATCH_THREADS threads (Windows' own under wine), restarted at theta 0,
   and fails unless every instance gives, at every point, the bits of the FMI calls made here one
   by one (the batch steps by a constant step from k * STEP_SIZE, where cs_loop_run steps by the
   differences of its points, which round differently).

   usage: cs_loop_harness LOOP_LIBRARY LIBRARY GUID STEPS STEP_SIZE 0 [TRAJECTORY]
   (after LOOP_LIBRARY, the command line of the bare masters, benchmarks/bare_master.h; the
   tolerance must be 0, undefined, as the loop's restart leaves it) */

#include <stdint.h>
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

typedef struct CsPool CsPool;
typedef CsPool *CsLoopBatchPoolNew(size_t n_threads);
typedef void CsLoopBatchPoolFree(CsPool *pool);
/* CsBatch of _cs_batch.c, field for field, as _batch.py mirrors it too. */
typedef struct {
    void *const *fmi;
    fmi2Component *components;
    size_t n_instances;
    const fmi2ValueReference *start_references;
    size_t n_start;
    const double *start_values;
    const unsigned char *modes;
    const double *tolerance;
    double start_time;
    const fmi2ValueReference *input_references;
    size_t n_inputs;
    const double *inputs;
    const fmi2ValueReference *output_references;
    size_t n_outputs;
    double *outputs;
    uint64_t *steps;
    double step_size;
    int *statuses;
    int *failed_calls;
} CsBatch;
typedef int CsLoopBatchAdvance(CsPool *pool, const CsBatch *batch);
enum { BATCH = 5, BATCH_THREADS = 2, BATCH_STEP = 0, BATCH_RESTART = 1 };

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

/* Theta at every point of one instance initialized at theta 0 and stepped by the FMI calls
   themselves, as the batch steps each of its instances. */
static void run_calls(void *const *functions, fmi2Component fmu, size_t steps, double step_size, double *theta) {
    fmi2SetupExperimentTYPE *const setup = (fmi2SetupExperimentTYPE *)functions[1];
    fmi2EnterInitializationModeTYPE *const enter = (fmi2EnterInitializationModeTYPE *)functions[2];
    fmi2ExitInitializationModeTYPE *const exit_initialization = (fmi2ExitInitializationModeTYPE *)functions[3];
    fmi2SetRealTYPE *const set_real = (fmi2SetRealTYPE *)functions[4];
    fmi2GetRealTYPE *const get_real = (fmi2GetRealTYPE *)functions[6];
    fmi2DoStepTYPE *const do_step = (fmi2DoStepTYPE *)functions[7];
    const fmi2ValueReference torque_vr = VR_TORQUE, theta_vr = VR_THETA;
    const double theta0 = 0.0, torque = TORQUE;
    check(setup(fmu, fmi2False, 0.0, 0.0, fmi2False, 0.0), "fmi2SetupExperiment", 0);
    check(enter(fmu), "fmi2EnterInitializationMode", 0);
    check(set_real(fmu, &theta_vr, 1, &theta0), "fmi2SetReal", 0);
    check(exit_initialization(fmu), "fmi2ExitInitializationMode", 0);
    check(get_real(fmu, &theta_vr, 1, &theta[0]), "fmi2GetReal", 0);
    for (size_t k = 0; k < steps; k++) {
        check(set_real(fmu, &torque_vr, 1, &torque), "fmi2SetReal", (long)k);
        check(do_step(fmu, (double)k * step_size, step_size, fmi2True), "fmi2DoStep", (long)k);
        check(get_real(fmu, &theta_vr, 1, &theta[k + 1]), "fmi2GetReal", (long)k);
    }
}

/* BATCH instances stepped together, each restarted at theta 0 and held at TORQUE; 0 when each
   instance's theta is expected[k] at every point k, else 1. */
static int run_batch(const Library loop, void *const *functions, fmi2Component *components, size_t steps,
                     double step_size, const double *expected) {
    CsLoopBatchPoolNew *const pool_new = (CsLoopBatchPoolNew *)symbol(loop, "cs_loop_batch_pool_new");
    CsLoopBatchPoolFree *const pool_free = (CsLoopBatchPoolFree *)symbol(loop, "cs_loop_batch_pool_free");
    CsLoopBatchAdvance *const advance = (CsLoopBatchAdvance *)symbol(loop, "cs_loop_batch_advance");
    const fmi2ValueReference torque_vr = VR_TORQUE, theta_vr = VR_THETA;
    double start_values[BATCH] = {0}, inputs[BATCH], outputs[BATCH];
    uint64_t steps_taken[BATCH];
    unsigned char modes[BATCH];
    int statuses[BATCH], failed_calls[BATCH];
    for (size_t i = 0; i < BATCH; i++) inputs[i] = TORQUE;
    const CsBatch batch = {functions, components, BATCH, &theta_vr, 1, start_values, modes, NULL, 0.0,
                           &torque_vr, 1, inputs, &theta_vr, 1, outputs, steps_taken, step_size, statuses,
                           failed_calls};
    CsPool *const pool = pool_new(BATCH_THREADS);
    if (!pool) {
        fprintf(stderr, MASTER_NAME ": no pool of %d threads\n", BATCH_THREADS);
        return 1;
    }
    int differs = 0;
    for (size_t k = 0; k <= steps && !differs; k++) {
        memset(modes, k == 0 ? BATCH_RESTART : BATCH_STEP, sizeof modes);
        check(advance(pool, &batch), "cs_loop_batch_advance", (long)k);
        for (size_t i = 0; i < BATCH; i++) differs |= memcmp(&outputs[i], &expected[k], sizeof *outputs) != 0;
        if (differs) fprintf(stderr, MASTER_NAME ": the batch differs from the loop at step %lu\n", (unsigned long)k);
    }
    pool_free(pool);
    return differs;
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

    fmi2Component batch[BATCH + 1];
    for (size_t i = 0; i <= BATCH; i++) {
        batch[i] = fmi2Instantiate("batch", fmi2CoSimulation, run.token, "", &callbacks, fmi2False, fmi2False);
        if (!batch[i]) return 1;
    }
    run_calls(functions, batch[BATCH], steps, run.step_size, restarted);
    if (run_batch(loop, functions, batch, steps, run.step_size, restarted) != 0) return 1;
    for (size_t i = 0; i <= BATCH; i++) fmi2FreeInstance(batch[i]);

    fmi2FreeInstance(fmu);
    close_library(run.library);
    close_library(loop);
    free(time);
    free(torque);
    free(theta);
    free(restarted);
    return 0;
}
