/* The Taylor series method, and DOPRI5 where the Taylor method gives up.

   Each internal step expands the states about the step's start in their Taylor series of order
   TAYLOR_ORDER, whose coefficients the model computes by recurrences (model_taylor_series), scaled
   by powers of the step: the rows summed are the state at the step's end, and the last row is
   the error estimate (of the series one order shorter; the one summed is more exact still). A
   step whose last row is beyond the tolerance shrinks until it meets it, by rescaling the rows:
   the coefficients do not depend on the step, so no step is rejected and computed again. */

#include <math.h>

#include "integrator.h"

/* A step tries at most MAX_FACTOR times the last; one shrunk to the tolerance aims at SAFETY
   times the size that meets it. */
#define SAFETY 0.9
#define MAX_FACTOR 5.0
/* At or below this ratio of error to tolerance the next step may be MAX_FACTOR times longer
   anyway, (SAFETY / MAX_FACTOR)^TAYLOR_ORDER: it skips a pow() in the steps that run most. */
#define RATIO_FOR_MAX_FACTOR 3.4012224e-5

/* Whether every state's last row is within `ratio` times its tolerance, atol + rtol * |state|
   (not when a row is NaN). */
static int within(double series[TAYLOR_ORDER + 1][N_STATES], double ratio, double rtol,
                  double atol) {
    int inside = 1;
    for (int i = 0; i < N_STATES; i++)
        inside &= fabs(series[TAYLOR_ORDER][i]) <= ratio * (atol + rtol * fabs(series[0][i]));
    return inside;
}

/* The largest ratio of a state's last row to its tolerance; not finite when a row is not. */
static double error_ratio(double series[TAYLOR_ORDER + 1][N_STATES], double rtol, double atol) {
    double largest = 0.0;
    for (int i = 0; i < N_STATES; i++) {
        const double ratio = fabs(series[TAYLOR_ORDER][i]) / (atol + rtol * fabs(series[0][i]));
        /* NaN compares false: keep it, so that the caller sees it. */
        largest = ratio > largest || ratio != ratio ? ratio : largest;
    }
    return largest;
}

/* Integrates as integrate() does with the Taylor method and returns 1, or returns 0, x and
   *step_size untouched, when the model has no series, a series is not finite, or the steps the
   tolerance needs run past max_steps or below h_min. */
static int taylor(SeriesFunction series_of, const void *context, double x[N_STATES], double length,
                  double rtol, double atol, long max_steps, double *step_size, long *steps_taken) {
    double series[TAYLOR_ORDER + 1][N_STATES];
    double offset = 0.0;
    double h = *step_size > 0.0 ? *step_size : length;
    /* A step this small relative to the interval means the tolerance cannot be met. */
    const double h_min = 1e-12 * length;
    long steps = 0;
    int i, k;

    for (i = 0; i < N_STATES; i++) series[0][i] = x[i];
    while (offset < length) {
        if (steps >= max_steps) return 0;
        const double remaining = length - offset;
        /* Stretch a step that would leave a sliver of less than 1e-8 h before the end. */
        int last = h >= remaining * (1.0 - 1e-8);
        double h_step = last ? remaining : h;

        if (!series_of(context, offset, h_step, series)) return 0;
        double h_next = h_step * MAX_FACTOR;
        if (!within(series, RATIO_FOR_MAX_FACTOR, rtol, atol)) {
            const double ratio = error_ratio(series, rtol, atol);
            if (!(ratio < INFINITY)) return 0;
            /* The factor that brings the last row to SAFETY^TAYLOR_ORDER of the tolerance. */
            const double factor = SAFETY * pow(ratio, -1.0 / TAYLOR_ORDER);
            if (ratio > 1.0) {
                h_step *= factor;
                last = 0;
                if (h_step < h_min) return 0;
                double power = factor;
                for (k = 1; k <= TAYLOR_ORDER; k++, power *= factor)
                    for (i = 0; i < N_STATES; i++) series[k][i] *= power;
            }
            h_next = h_step * (ratio > 1.0 ? 1.0 : factor);
        }
        steps++;

        /* The state h_step later: the smallest rows first. */
        double sum[N_STATES];
        for (i = 0; i < N_STATES; i++) sum[i] = series[TAYLOR_ORDER][i];
        for (k = TAYLOR_ORDER - 1; k >= 0; k--)
            for (i = 0; i < N_STATES; i++) sum[i] += series[k][i];
        for (i = 0; i < N_STATES; i++) {
            if (!isfinite(sum[i])) return 0;
            series[0][i] = sum[i];
        }
        if (last) {
            offset = length;
            /* A step cut short to land on the end says nothing against the longer one. */
            *step_size = h_next > h ? h_next : h;
        } else {
            offset += h_step;
            h = h_next;
        }
    }

    for (i = 0; i < N_STATES; i++) x[i] = series[0][i];
    *steps_taken = steps;
    return 1;
}

IntegrationResult integrate(OdeFunction f, SeriesFunction series, const void *context,
                            double x[N_STATES], double length, double rtol, double atol,
                            long max_steps, double *step_size, long *steps_taken) {
    if (taylor(series, context, x, length, rtol, atol, max_steps, step_size, steps_taken))
        return INTEGRATION_OK;
    switch (dopri5_integrate(f, context, x, length, rtol, atol, max_steps, step_size, steps_taken)) {
        case DOPRI5_OK: return INTEGRATION_OK;
        case DOPRI5_STEP_BUDGET_EXHAUSTED: return INTEGRATION_STEP_BUDGET_EXHAUSTED;
        default: return INTEGRATION_STEP_TOO_SMALL;
    }
}
