/* A bare FMI 2.0 co-simulation master, so that callgrind sees the FMU's instructions and almost
   nothing else: no interpreter, no wrapper. It runs the tutorial loop (set the torque, step, read
   theta) and can write theta at every step, so a run can be checked. It builds for Linux and,
   cross-compiled, for Windows, where the tests run it under wine against the DLL.
   fmi3_step_master.c is the same master for FMI 3.0.

   usage: step_master LIBRARY GUID STEPS STEP_SIZE TOLERANCE [TRAJECTORY]
   TOLERANCE 0 leaves it undefined, so the FMU uses its default. */

#include "fmi2Functions.h"

#define MASTER_NAME "step_master"
#define MASTER_TOKEN "GUID"
#include "bare_master.h"

static void logger(fmi2ComponentEnvironment environment, fmi2String instance_name,
                   fmi2Status status, fmi2String category, fmi2String message, ...) {
    (void)environment;
    fprintf(stderr, "%s [%s] status %d: %s\n", instance_name, category, (int)status, message);
}

int main(int argc, char **argv) {
    const MasterRun run = start_master(argc, argv);
    LOOK_UP(run.library, fmi2Instantiate);
    LOOK_UP(run.library, fmi2SetupExperiment);
    LOOK_UP(run.library, fmi2EnterInitializationMode);
    LOOK_UP(run.library, fmi2ExitInitializationMode);
    LOOK_UP(run.library, fmi2SetReal);
    LOOK_UP(run.library, fmi2GetReal);
    LOOK_UP(run.library, fmi2DoStep);
    LOOK_UP(run.library, fmi2Terminate);
    LOOK_UP(run.library, fmi2FreeInstance);

    const fmi2CallbackFunctions callbacks = {logger, NULL, NULL, NULL, NULL};
    fmi2Component fmu = fmi2Instantiate("master", fmi2CoSimulation, run.token, "", &callbacks,
                                        fmi2False, fmi2False);
    if (!fmu) return 1;
    check(fmi2SetupExperiment(fmu, run.tolerance > 0, run.tolerance, 0.0, fmi2False, 0.0),
          "fmi2SetupExperiment", 0);
    check(fmi2EnterInitializationMode(fmu), "fmi2EnterInitializationMode", 0);
    check(fmi2ExitInitializationMode(fmu), "fmi2ExitInitializationMode", 0);

    const fmi2ValueReference torque_vr = VR_TORQUE, theta_vr = VR_THETA;
    const double torque = TORQUE;
    double theta;
    check(fmi2GetReal(fmu, &theta_vr, 1, &theta), "fmi2GetReal", 0);
    record_theta(&run, theta);
    for (long k = 0; k < run.steps; k++) {
        /* Time as n*h, not a running sum, so it never drifts from where the FMU stands. */
        const double time = k * run.step_size;
        check(fmi2SetReal(fmu, &torque_vr, 1, &torque), "fmi2SetReal", k);
        check(fmi2DoStep(fmu, time, run.step_size, fmi2True), "fmi2DoStep", k);
        check(fmi2GetReal(fmu, &theta_vr, 1, &theta), "fmi2GetReal", k);
        record_theta(&run, theta);
    }
    close_trajectory(&run);

    fmi2Terminate(fmu);
    fmi2FreeInstance(fmu);
    close_library(run.library);
    return 0;
}
