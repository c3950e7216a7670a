/* The oracle's Taylor stepping (pendulum_fmu/oracle/_taylor.py, integrate_piece) in C, for a
   whole window of runs of linear torque in one call: what integrate_window (_integration.py)
   loops over in Python, one run after another, carrying theta and omega across.

   It is the Python integrator transcribed: the same floating-point operations in the same order
   (the recurrences, the Horner sums of _sum, numpy's polyval for many reports in one step, libm's
   sin, cos and pow as Python's math module and ** call them), built without FMA contraction
   (cmake/flags.cmake), so that the two give the same numbers bit for bit and either can stand for
   the other (tests/test_taylor_native.py). It shares nothing with the FMU's integrator
   (fmu_src/): the oracle stays independent of what it judges. It is compiled into the native
   loop's library (_cs_loop, CMakeLists.txt) only to travel in the same file of every wheel, and
   allocates nothing: the series' coefficients are fixed arrays, as the order is at most
   TAYLOR_MAX_ORDER (_taylor.order_limit). */

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#define TAYLOR_EXPORT __declspec(dllexport)
#else
#define TAYLOR_EXPORT __attribute__((visibility("default")))
#endif

#define TAYLOR_MAX_ORDER 30
/* _taylor._FEW: up to this many reports in a step are summed as _sum does, more as polyval. */
#define TAYLOR_FEW 8

/* What cs_loop_taylor_window returns; _taylor_native.py words each failure as _taylor.py raises
   it. TAYLOR_PAUSED: the steps asked for are taken, call again to go on. */
enum { TAYLOR_OK = 0, TAYLOR_COEFFICIENT = 1, TAYLOR_UNDERFLOW = 2, TAYLOR_STATE = 3, TAYLOR_PAUSED = 4 };

/* Changes whenever cs_loop_taylor_window's arguments do (_taylor_native.py checks it). */
TAYLOR_EXPORT int cs_loop_taylor_interface(void) { return 2; }

/* _taylor._sum: Horner's rule from the last coefficient. */
static double sum_series(const double *coefficients, int n, double tau)
{
    double total = coefficients[n - 1];
    int i;
    for (i = n - 2; i >= 0; i--) total = total * tau + coefficients[i];
    return total;
}

/* numpy.polyval of the reversed coefficients: Horner's rule from zero, which differs from
   sum_series in the sign of a zero only, but the oracle's numbers are to be the same bits. */
static double polyval(const double *coefficients, int n, double tau)
{
    double total = 0.0;
    int i;
    for (i = n - 1; i >= 0; i--) total = total * tau + coefficients[i];
    return total;
}

static double clipped(double time, double start, double end)
{
    /* numpy.clip: the maximum with start, then the minimum with end. */
    double above = time < start ? start : time;
    return above > end ? end : above;
}

typedef struct {
    double gravity_moment, damping, inverse_inertia, rtol, atol;
    int order;
} Model;

/* One run of integrate_piece: from state (theta, omega at time t) to end under
   u0 + rate*(t - start), thetas[i], omegas[i] at reports[i] clipped into [start, end], from
   report *next_io on. Each step takes one of *budget; where none is left before the end, the
   state and *next_io say where the run stands and it returns TAYLOR_PAUSED. A step starts from
   theta, omega and t alone, so a run taken up again gives the bits of one run straight through. */
static int integrate_run(const Model *model, double *state, size_t *next_io, double start, double end, double u0,
                         double rate, const double *reports, size_t n_reports, double *thetas, double *omegas,
                         long *budget, double *failed_time)
{
    double x[TAYLOR_MAX_ORDER + 2], v[TAYLOR_MAX_ORDER + 1];
    double sines[TAYLOR_MAX_ORDER], cosines[TAYLOR_MAX_ORDER];
    double theta = state[0], omega = state[1], t = state[2], reach = INFINITY;
    size_t next_report = *next_io;

    for (;;) {
        const double remaining = end - t;
        const double size = fabs(omega) > fabs(theta) ? fabs(omega) : fabs(theta);
        const double bound = model->atol + model->rtol * size;
        const double u_start = u0 + rate * (t - start);
        double step, stop;
        size_t upto, i;
        int k;

        x[0] = theta;
        x[1] = omega;
        v[0] = omega;
        sines[0] = sin(theta);
        cosines[0] = cos(theta);
        for (k = 0;; k++) {
            const double u = k == 0 ? u_start : (k == 1 ? rate : 0.0);
            double terms[4];
            int powers[4], m;
            if (k) {
                double sine = 0.0, cosine = 0.0;
                int j;
                for (j = 1; j <= k; j++) {
                    const double jx = (double)j * x[j];
                    sine += jx * cosines[k - j];
                    cosine += jx * sines[k - j];
                }
                sines[k] = sine / (double)k;
                cosines[k] = -cosine / (double)k;
            }
            v[k + 1] = (u - model->gravity_moment * sines[k] - model->damping * v[k]) * model->inverse_inertia /
                       (double)(k + 1);
            x[k + 2] = v[k + 1] / (double)(k + 2);
            terms[0] = x[k + 2], powers[0] = k + 2;
            terms[1] = x[k + 1], powers[1] = k + 1;
            terms[2] = v[k + 1], powers[2] = k + 1;
            terms[3] = v[k], powers[3] = k;
            for (m = 0; m < 4; m++) {
                if (!isfinite(terms[m])) return TAYLOR_COEFFICIENT;
            }
            if (k) {
                reach = INFINITY;
                for (m = 0; m < 4; m++) {
                    const double r = terms[m] != 0.0 ? pow(bound / fabs(terms[m]), 1.0 / (double)powers[m])
                                                     : INFINITY;
                    if (r < reach) reach = r;
                }
                if (remaining <= reach) break;
            }
            if (k == model->order - 1) break;
        }
        /* theta's terms up to order k+2, omega's up to k+1. */
        step = reach < remaining ? reach : remaining;
        stop = step == remaining ? end : t + step;
        if (stop <= t && t < end) {
            *failed_time = t;
            return TAYLOR_UNDERFLOW;
        }
        upto = next_report;
        if (stop == end) {
            upto = n_reports;
        } else {
            while (upto < n_reports && clipped(reports[upto], start, end) <= stop) upto++;
        }
        if (upto - next_report > TAYLOR_FEW) {
            for (i = next_report; i < upto; i++) {
                const double tau = clipped(reports[i], start, end) - t;
                thetas[i] = polyval(x, k + 3, tau);
                omegas[i] = polyval(v, k + 2, tau);
            }
        } else {
            for (i = next_report; i < upto; i++) {
                const double tau = clipped(reports[i], start, end) - t;
                thetas[i] = sum_series(x, k + 3, tau);
                omegas[i] = sum_series(v, k + 2, tau);
            }
        }
        next_report = upto;
        theta = sum_series(x, k + 3, stop - t);
        omega = sum_series(v, k + 2, stop - t);
        if (!(isfinite(theta) && isfinite(omega))) return TAYLOR_STATE;
        t = stop;
        --*budget;
        if (t == end || *budget <= 0) {
            state[0] = theta;
            state[1] = omega;
            state[2] = t;
            *next_io = next_report;
            return t == end ? TAYLOR_OK : TAYLOR_PAUSED;
        }
    }
}

/* Integrates runs position[0]..until-1 of a window, each from the state the one before reached,
   taking at most budget Taylor steps (then TAYLOR_PAUSED: call again, with what it left in state
   and position, to go on), so that the caller's progress bar and Ctrl-C are heard within a run.

   state[0..2]               theta, omega and the time they hold at (the first run's start, at the
                             first call); on return, where the integration stands
   position[0], position[1]  the run it stands in, and its next report (0 at a run's start)
   starts[r], ends[r]        run r's span, in s
   u0s[r], rates[r]          its torque at its start and the torque's rate
   bounds[r], bounds[r + 1]  its reports: reports[bounds[r]..bounds[r + 1]), sorted, clipped
                             into its span as integrate_window does
   model[0..4]               mass*gravity*length, damping, 1/inertia, rtol and atol
   order                     _taylor.order_limit(min(rtol, atol)), at most TAYLOR_MAX_ORDER
   thetas[i], omegas[i]      written: the state at reports[i]

   Returns TAYLOR_OK once run until-1 ends; TAYLOR_PAUSED; -1 for an order the arrays cannot hold;
   or the failure's TAYLOR_ code, position[0] its run and, for TAYLOR_UNDERFLOW, *failed_time the
   time the step underflows at. */
TAYLOR_EXPORT int cs_loop_taylor_window(double *state, int64_t *position, size_t until, const double *starts,
                                        const double *ends, const double *u0s, const double *rates,
                                        const int64_t *bounds, const double *reports, const double *model, int order,
                                        long budget, double *thetas, double *omegas, double *failed_time)
{
    const Model pendulum = {model[0], model[1], model[2], model[3], model[4], order};
    size_t r = (size_t)position[0];
    if (order < 2 || order > TAYLOR_MAX_ORDER) return -1;
    while (r < until) {
        const int64_t lo = bounds[r];
        size_t next = (size_t)position[1];
        const int status = integrate_run(&pendulum, state, &next, starts[r], ends[r], u0s[r], rates[r], reports + lo,
                                         (size_t)(bounds[r + 1] - lo), thetas + lo, omegas + lo, &budget, failed_time);
        position[1] = (int64_t)next;
        if (status != TAYLOR_OK) return status;
        position[0] = (int64_t)++r;
        position[1] = 0;
        if (r < until) {
            state[2] = starts[r];
            if (budget <= 0) return TAYLOR_PAUSED;
        }
    }
    return TAYLOR_OK;
}
