/* step_master.c's loop through FMI 3.0's co-simulation interface: the tests run it against the
   FMI 3.0 FMU's binary for each platform (natively, under wine, under qemu-aarch64), as they run
   step_master against the FMI 2.0 one.

   usage: fmi3_step_master LIBRARY INSTANTIATION_TOKEN STEPS STEP_SIZE TOLERANCE [TRAJECTORY]
   TOLERANCE 0 leaves it undefined, so the FMU uses its default. */

#include "fmi3Functions.h"

#define MASTER_NAME "fmi3_step_master"
#define MASTER_TOKEN "INSTANTIATION_TOKEN"
#include "bare_master.h"

static void logger(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category,
                   fmi3String message) {
    (void)environment;
    fprintf(stderr, "master [%s] status %d: %s\n", category, (int)status, message);
}

int main(int argc, char **argv) {
    const MasterRun run = start_master(argc, argv);
    LOOK_UP(run.library, fmi3InstantiateCoSimulation);
    LOOK_UP(run.library, fmi3EnterInitializationMode);
    LOOK_UP(run.library, fmi3ExitInitializationMode);
    LOOK_UP(run.library, fmi3SetFloat64);
    LOOK_UP(run.library, fmi3GetFloat64);
    LOOK_UP(run.library, fmi3DoStep);
    LOOK_UP(run.library, fmi3Terminate);
    LOOK_UP(run.library, fmi3FreeInstance);

    /* No event mode, no early return, no intermediate updates: FMI 3.0's plain co-simulation,
       the same loop as FMI 2.0's. */
    fmi3Instance fmu = fmi3InstantiateCoSimulation("master", run.token, NULL, fmi3False, fmi3False,
                                                   fmi3False, fmi3False, NULL, 0, NULL, logger, NULL);
    if (!fmu) return 1;
    check(fmi3EnterInitializationMode(fmu, run.tolerance > 0, run.tolerance, 0.0, fmi3False, 0.0),
          "fmi3EnterInitializationMode", 0);
    check(fmi3ExitInitializationMode(fmu), "fmi3ExitInitializationMode", 0);

    const fmi3ValueReference torque_vr = VR_TORQUE, theta_vr = VR_THETA;
    const double torque = TORQUE;
    double theta;
    check(fmi3GetFloat64(fmu, &theta_vr, 1, &theta, 1), "fmi3GetFloat64", 0);
    record_theta(&run, theta);
    for (long k = 0; k < run.steps; k++) {
        /* Time as n*h, not a running sum, so it never drifts from where the FMU stands. */
        const double time = k * run.step_size;
        fmi3Boolean event_handling_needed, terminate_simulation, early_return;
        fmi3Float64 last_successful_time;
        check(fmi3SetFloat64(fmu, &torque_vr, 1, &torque, 1), "fmi3SetFloat64", k);
        check(fmi3DoStep(fmu, time, run.step_size, fmi3True, &event_handling_needed,
                         &terminate_simulation, &early_return, &last_successful_time),
              "fmi3DoStep", k);
        /* The FMU never asks for either; a step that did would not have reached t + h. */
        if (terminate_simulation || early_return) {
            fprintf(stderr, MASTER_NAME ": fmi3DoStep stopped before t + h at step %ld\n", k);
            return 1;
        }
        check(fmi3GetFloat64(fmu, &theta_vr, 1, &theta, 1), "fmi3GetFloat64", k);
        record_theta(&run, theta);
    }
    close_trajectory(&run);

    fmi3Terminate(fmu);
    fmi3FreeInstance(fmu);
    close_library(run.library);
    return 0;
}
