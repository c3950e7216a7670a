/* A bare FMI 2.0 master that names the call record's file, for the platforms the tests can run
   (linux64 here, win64 under wine, aarch64-linux under qemu): it instantiates with the instance
   name given, sets callRecordFile, frees the instance and prints what the FMU logged.

   usage: record_master LIBRARY GUID INSTANCE_NAME RECORD_FILE */

#include "fmi2Functions.h"

#include <stdio.h>
#include <stdlib.h>

#define MASTER_NAME "record_master"
#define MASTER_TOKEN "GUID"
/* Its loading of the library, not its command line (start_master and the trajectory go unused). */
#pragma GCC diagnostic ignored "-Wunused-function"
#include "bare_master.h"

/* callRecordFile's value reference in the FMI 2.0 model description. */
#define VR_CALL_RECORD_FILE 9

static void logger(fmi2ComponentEnvironment environment, fmi2String instance_name,
                   fmi2Status status, fmi2String category, fmi2String message, ...) {
    (void)environment, (void)instance_name, (void)category;
    printf("[%d] %s\n", (int)status, message);
}

int main(int argc, char **argv) {
    if (argc != 5) {
        fprintf(stderr, "usage: %s LIBRARY GUID INSTANCE_NAME RECORD_FILE\n", argv[0]);
        return 2;
    }
    const Library library = open_library(argv[1]);
    if (!library) {
        fprintf(stderr, "cannot load %s: %s\n", argv[1], library_error());
        return 2;
    }
    LOOK_UP(library, fmi2Instantiate);
    LOOK_UP(library, fmi2SetString);
    LOOK_UP(library, fmi2FreeInstance);
    const fmi2CallbackFunctions callbacks = {logger, NULL, NULL, NULL, NULL};
    fmi2Component fmu = fmi2Instantiate(argv[3], fmi2CoSimulation, argv[2], "", &callbacks,
                                        fmi2False, fmi2False);
    if (!fmu) {
        /* Said, so that a refused instantiation is told apart from wine failing to start. */
        fprintf(stderr, "fmi2Instantiate returned NULL\n");
        return 1;
    }
    const fmi2ValueReference reference = VR_CALL_RECORD_FILE;
    const fmi2String file = argv[4];
    printf("fmi2SetString: %d\n", (int)fmi2SetString(fmu, &reference, 1, &file));
    fmi2FreeInstance(fmu);
    close_library(library);
    return 0;
}
