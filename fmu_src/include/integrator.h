#ifndef INTEGRATOR_H
#define INTEGRATOR_H

#include "dopri5.h"

/* model_taylor_series (model.h) of an instance. */
typedef int (*SeriesFunction)(const void *context, double offset, double h,
                              double series[TAYLOR_ORDER + 1][N_STATES]);

typedef enum {
    INTEGRATION_OK,
    INTEGRATION_STEP_BUDGET_EXHAUSTED,
    INTEGRATION_STEP_TOO_SMALL
} IntegrationResult;

/* Integrates x over offsets [0, length] as dopri5_integrate does (same arguments; error control
   per component |err| <= atol + rtol*|x|) by the Taylor series method (integrator.c) with
   `series`; where that gives up (the model has no series, a series is not finite, or the
   tolerance needs more than max_steps steps or steps below 1e-12 length), by DOPRI5 (dopri5.c)
   with f, from the start again. */
IntegrationResult integrate(OdeFunction f, SeriesFunction series, const void *context,
                            double x[N_STATES], double length, double rtol, double atol,
                            long max_steps, double *step_size, long *steps_taken);

#endif
