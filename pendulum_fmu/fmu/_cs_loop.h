/* What the native loop's two files share (_cs_loop.c, _cs_batch.c): the export mark, the FMU's
   functions as Python hands them over, and the calls a failure is reported by. */

#ifndef CS_LOOP_H
#define CS_LOOP_H

#include <stddef.h>

#include "fmi2FunctionTypes.h"

#if defined(_WIN32)
#define CS_LOOP_EXPORT __declspec(dllexport)
#else
#define CS_LOOP_EXPORT __attribute__((visibility("default")))
#endif

/* The FMU's functions, in this order (_native_loop.py passes them as an array of addresses). */
typedef struct {
    fmi2ResetTYPE *reset;
    fmi2SetupExperimentTYPE *setup_experiment;
    fmi2EnterInitializationModeTYPE *enter_initialization_mode;
    fmi2ExitInitializationModeTYPE *exit_initialization_mode;
    fmi2SetRealTYPE *set_real;
    fmi2SetRealInputDerivativesTYPE *set_real_input_derivatives;
    fmi2GetRealTYPE *get_real;
    fmi2DoStepTYPE *do_step;
} CsFunctions;

/* Which call failed, as reported through *failed_call. */
enum { CALL_SET_REAL = 0, CALL_SET_RATE = 1, CALL_GET_REAL = 2, CALL_DO_STEP = 3,
       CALL_GET_OUTPUTS_AT_END = 4, CALL_RESET = 5, CALL_SETUP_EXPERIMENT = 6,
       CALL_ENTER_INITIALIZATION_MODE = 7, CALL_SET_START_VALUES = 8,
       CALL_EXIT_INITIALIZATION_MODE = 9 };

typedef struct CsPool CsPool;
CS_LOOP_EXPORT void cs_loop_batch_pool_free(CsPool *pool);

#endif
