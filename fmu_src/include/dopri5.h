#ifndef DOPRI5_H
#define DOPRI5_H

#include "model.h"

/* Dormand-Prince 5(4): an embedded Runge-Kutta pair, order 5 propagated, order 4 for the error
   estimate. Exact (to rounding) for solutions that are polynomials of degree 5 or less. */

typedef void (*OdeFunction)(const void *context, double offset, const double x[N_STATES],
                            double dx[N_STATES]);

typedef enum {
    DOPRI5_OK,
    DOPRI5_STEP_BUDGET_EXHAUSTED,
    DOPRI5_STEP_TOO_SMALL
} Dopri5Result;

/* Integrates x over offsets [0, length]; internal steps end exactly on length and never cross it.
   Error control per component: |err| <= atol + rtol*max(|x_old|, |x_new|).
   *step_size carries the proposed internal step from one call to the next (0: try the whole
   interval first). At most max_steps steps (accepted or rejected) are tried. x is changed only
   when the whole interval is done. Uses no heap. */
Dopri5Result dopri5_integrate(OdeFunction f, const void *context, double x[N_STATES], double length,
                              double rtol, double atol, long max_steps, double *step_size,
                              long *steps_taken);

#endif
