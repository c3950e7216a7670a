#include <math.h>

#include "dopri5.h"

/* Butcher tableau of Dormand & Prince (1980), as in Hairer, Norsett & Wanner, Solving ODE I. */
static const double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
static const double a21 = 1.0 / 5;
static const double a31 = 3.0 / 40, a32 = 9.0 / 40;
static const double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
static const double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
                    a54 = -212.0 / 729;
static const double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247,
                    a64 = 49.0 / 176, a65 = -5103.0 / 18656;
static const double b1 = 35.0 / 384, b3 = 500.0 / 1113, b4 = 125.0 / 192, b5 = -2187.0 / 6784,
                    b6 = 11.0 / 84;
/* Difference between the 5th- and the embedded 4th-order weights. */
static const double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920,
                    e5 = -17253.0 / 339200, e6 = 22.0 / 525, e7 = -1.0 / 40;

/* Step-size controller: h_new = h * SAFETY * err^(-1/5), the factor kept in [MIN, MAX]. */
#define SAFETY 0.9
#define MIN_FACTOR 0.2
#define MAX_FACTOR 5.0
/* Below this error the factor is MAX_FACTOR anyway: (SAFETY/MAX_FACTOR)^5; skips a pow(). */
#define ERROR_FOR_MAX_FACTOR 1.889568e-4

static double step_factor(double error) {
    if (error <= ERROR_FOR_MAX_FACTOR) return MAX_FACTOR;
    const double factor = SAFETY * pow(error, -0.2);
    return factor < MIN_FACTOR ? MIN_FACTOR : (factor > MAX_FACTOR ? MAX_FACTOR : factor);
}

Dopri5Result dopri5_integrate(OdeFunction f, const void *context, double x[N_STATES], double length,
                              double rtol, double atol, long max_steps, double *step_size,
                              long *steps_taken) {
    double y[N_STATES], y_stage[N_STATES], y_new[N_STATES];
    double k1[N_STATES], k2[N_STATES], k3[N_STATES], k4[N_STATES], k5[N_STATES], k6[N_STATES],
           k7[N_STATES];
    double offset = 0.0;
    double h = *step_size > 0.0 ? *step_size : length;
    /* A step this small relative to the interval means the tolerance cannot be met. */
    const double h_min = 1e-12 * length;
    long steps = 0;
    int i;

    for (i = 0; i < N_STATES; i++) y[i] = x[i];
    f(context, 0.0, y, k1);

    while (offset < length) {
        if (steps >= max_steps) {
            *steps_taken = steps;
            return DOPRI5_STEP_BUDGET_EXHAUSTED;
        }
        if (h < h_min) {
            *steps_taken = steps;
            return DOPRI5_STEP_TOO_SMALL;
        }
        const double remaining = length - offset;
        /* Stretch a step that would leave a sliver of less than 1e-8 h before the end. */
        const int last = h >= remaining * (1.0 - 1e-8);
        const double h_step = last ? remaining : h;
        steps++;

        for (i = 0; i < N_STATES; i++) y_stage[i] = y[i] + h_step * a21 * k1[i];
        f(context, offset + c2 * h_step, y_stage, k2);
        for (i = 0; i < N_STATES; i++) y_stage[i] = y[i] + h_step * (a31 * k1[i] + a32 * k2[i]);
        f(context, offset + c3 * h_step, y_stage, k3);
        for (i = 0; i < N_STATES; i++)
            y_stage[i] = y[i] + h_step * (a41 * k1[i] + a42 * k2[i] + a43 * k3[i]);
        f(context, offset + c4 * h_step, y_stage, k4);
        for (i = 0; i < N_STATES; i++)
            y_stage[i] = y[i] + h_step * (a51 * k1[i] + a52 * k2[i] + a53 * k3[i] + a54 * k4[i]);
        f(context, offset + c5 * h_step, y_stage, k5);
        for (i = 0; i < N_STATES; i++)
            y_stage[i] = y[i] + h_step * (a61 * k1[i] + a62 * k2[i] + a63 * k3[i] + a64 * k4[i]
                                          + a65 * k5[i]);
        f(context, offset + h_step, y_stage, k6);
        for (i = 0; i < N_STATES; i++)
            y_new[i] = y[i] + h_step * (b1 * k1[i] + b3 * k3[i] + b4 * k4[i] + b5 * k5[i]
                                        + b6 * k6[i]);
        f(context, offset + h_step, y_new, k7);

        double error = 0.0;
        for (i = 0; i < N_STATES; i++) {
            const double estimate = h_step * (e1 * k1[i] + e3 * k3[i] + e4 * k4[i] + e5 * k5[i]
                                              + e6 * k6[i] + e7 * k7[i]);
            const double scale = atol + rtol * fmax(fabs(y[i]), fabs(y_new[i]));
            const double ratio = fabs(estimate) / scale;
            /* NaN compares false: a non-finite stage makes the step fail below. */
            error = ratio > error || ratio != ratio ? ratio : error;
        }

        if (!(error <= 1.0)) {
            h = h_step * (error == error ? step_factor(error) : MIN_FACTOR);
            continue;
        }

        const double h_proposed = h_step * step_factor(error);
        for (i = 0; i < N_STATES; i++) {
            y[i] = y_new[i];
            k1[i] = k7[i];  /* first same as last */
        }
        if (last) {
            offset = length;
            /* A step cut short to land on the end says nothing against the longer one. */
            *step_size = h_proposed > h ? h_proposed : h;
        } else {
            offset += h_step;
            h = h_proposed;
        }
    }

    for (i = 0; i < N_STATES; i++) x[i] = y[i];
    *steps_taken = steps;
    return DOPRI5_OK;
}
