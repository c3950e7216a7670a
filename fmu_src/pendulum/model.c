/* The torque-driven pendulum:
       I_total * alpha = torque - mass*gravity*length*sin(theta) - damping*omega
       I_total = inertia + mass*length^2
   inertia is the head's own moment about its centre, moved to the pivot by the parallel-axis
   theorem. Everything here is SI. */

#include <math.h>
#include <stddef.h>

#include "model.h"

/* The states' places in x[] and in each row of a Taylor series. */
enum { THETA, OMEGA };

const char *model_invalid_parameters(const double values[N_VARIABLES]) {
    if (!(values[VR_MASS] > 0)) return "mass must be > 0";
    if (!(values[VR_LENGTH] >= 0)) return "length must be >= 0";
    if (!(values[VR_INERTIA] >= 0)) return "inertia must be >= 0";
    if (!(values[VR_DAMPING] >= 0)) return "damping must be >= 0";
    if (!isfinite(values[VR_GRAVITY])) return "gravity must be finite";
    const double inertia_total = values[VR_INERTIA] + values[VR_MASS] * values[VR_LENGTH] * values[VR_LENGTH];
    if (!(inertia_total > 0) || !isfinite(inertia_total))
        return "inertia + mass*length^2 (the inertia about the pivot) must be > 0 and finite";
    return NULL;
}

void model_coefficients(const double values[N_VARIABLES], ModelCoefficients *coefficients) {
    const double mass = values[VR_MASS], length = values[VR_LENGTH];
    coefficients->gravity_moment = mass * values[VR_GRAVITY] * length;
    coefficients->damping = values[VR_DAMPING];
    coefficients->inverse_inertia = 1.0 / (values[VR_INERTIA] + mass * length * length);
}

void model_get_states(const double values[N_VARIABLES], double x[N_STATES]) {
    x[THETA] = values[VR_THETA];
    x[OMEGA] = values[VR_OMEGA];
}

void model_set_states(double values[N_VARIABLES], const double x[N_STATES]) {
    values[VR_THETA] = x[THETA];
    values[VR_OMEGA] = x[OMEGA];
}

static double acceleration(const ModelCoefficients *k, double theta, double omega, double torque) {
    return (torque - k->gravity_moment * sin(theta) - k->damping * omega) * k->inverse_inertia;
}

void model_derivatives(const ModelCoefficients *coefficients, const double values[N_VARIABLES],
                       const InputDerivatives *inputs, double offset,
                       const double x[N_STATES], double dx[N_STATES]) {
    const double torque = input_at(values, inputs, VR_TORQUE, offset);
    dx[0] = x[1];
    dx[1] = acceleration(coefficients, x[0], x[1], torque);
}

/* Fails to compile unless the series below is of the order the integrator asks for. */
typedef char series_is_of_taylor_order[TAYLOR_ORDER == 6 ? 1 : -1];

int model_taylor_series(const ModelCoefficients *k, const double values[N_VARIABLES],
                        const InputDerivatives *inputs, double offset, double h,
                        double series[TAYLOR_ORDER + 1][N_STATES]) {
    /* Row n (h^n/n! times the n-th derivative) of omega (w), sin(theta) (s), cos(theta) (c)
       and the torque, from the rows before it: I_total omega' = torque - G sin(theta) - D omega,
       (sin theta)' = cos(theta) omega, (cos theta)' = -sin(theta) omega; each row n carries a
       factor h/n over the products of rows before it. The torque's polynomial ends at row 2. */
    const double G = k->gravity_moment, D = k->damping, I = k->inverse_inertia;
    const double h2 = h / 2, h3 = h / 3, h4 = h / 4, h5 = h / 5, h6 = h / 6;
    const double torque[3] = {input_at(values, inputs, VR_TORQUE, offset),
                              h * (inputs->first[VR_TORQUE] + offset * inputs->second[VR_TORQUE]),
                              h * h2 * inputs->second[VR_TORQUE]};
    double w[7], s[6], c[5];
    w[0] = series[0][OMEGA];
    s[0] = sin(series[0][THETA]);
    c[0] = cos(series[0][THETA]);
    w[1] = (torque[0] - G * s[0] - D * w[0]) * I * h;
    s[1] = c[0] * w[0] * h;
    c[1] = -s[0] * w[0] * h;
    w[2] = (torque[1] - G * s[1] - D * w[1]) * I * h2;
    s[2] = (c[0] * w[1] + c[1] * w[0]) * h2;
    c[2] = -(s[0] * w[1] + s[1] * w[0]) * h2;
    w[3] = (torque[2] - G * s[2] - D * w[2]) * I * h3;
    s[3] = (c[0] * w[2] + c[1] * w[1] + c[2] * w[0]) * h3;
    c[3] = -(s[0] * w[2] + s[1] * w[1] + s[2] * w[0]) * h3;
    w[4] = -(G * s[3] + D * w[3]) * I * h4;
    s[4] = (c[0] * w[3] + c[1] * w[2] + c[2] * w[1] + c[3] * w[0]) * h4;
    c[4] = -(s[0] * w[3] + s[1] * w[2] + s[2] * w[1] + s[3] * w[0]) * h4;
    w[5] = -(G * s[4] + D * w[4]) * I * h5;
    s[5] = (c[0] * w[4] + c[1] * w[3] + c[2] * w[2] + c[3] * w[1] + c[4] * w[0]) * h5;
    w[6] = -(G * s[5] + D * w[5]) * I * h6;
    /* theta' = omega */
    series[1][THETA] = w[0] * h;
    series[2][THETA] = w[1] * h2;
    series[3][THETA] = w[2] * h3;
    series[4][THETA] = w[3] * h4;
    series[5][THETA] = w[4] * h5;
    series[6][THETA] = w[5] * h6;
    for (int n = 1; n <= TAYLOR_ORDER; n++) series[n][OMEGA] = w[n];
    return 1;
}

void model_update_outputs(const ModelCoefficients *coefficients, double values[N_VARIABLES]) {
    values[VR_ALPHA] = acceleration(coefficients, values[VR_THETA], values[VR_OMEGA], values[VR_TORQUE]);
}

int model_output_derivative(const ModelCoefficients *k, const double values[N_VARIABLES],
                            const InputDerivatives *inputs, unsigned int vr, int order,
                            double *derivative) {
    const double theta = values[VR_THETA], omega = values[VR_OMEGA];
    const double alpha = acceleration(k, theta, omega, values[VR_TORQUE]);
    const double jerk = (inputs->first[VR_TORQUE] - k->gravity_moment * cos(theta) * omega
                         - k->damping * alpha) * k->inverse_inertia;
    const double snap = (inputs->second[VR_TORQUE]
                         + k->gravity_moment * (sin(theta) * omega * omega - cos(theta) * alpha)
                         - k->damping * jerk) * k->inverse_inertia;
    /* theta, omega, alpha are successive derivatives: the order-th derivative of the output
       at position p in that chain is the entry at p + order. */
    const double chain[5] = {theta, omega, alpha, jerk, snap};
    int position;
    switch (vr) {
        case VR_THETA: position = 0; break;
        case VR_OMEGA: position = 1; break;
        case VR_ALPHA: position = 2; break;
        default: return 0;
    }
    if (order < 1 || order > 2) return 0;
    *derivative = chain[position + order];
    return 1;
}

int model_partial_derivative(const ModelCoefficients *k, const double values[N_VARIABLES],
                             unsigned int unknown, unsigned int known, double *partial) {
    const int known_is_state = known == VR_THETA || known == VR_OMEGA;
    if (known != VR_TORQUE && !known_is_state) return 0;
    switch (unknown) {
        case VR_THETA:
        case VR_OMEGA:
            /* Outputs that are states depend only on themselves. */
            *partial = unknown == known ? 1.0 : 0.0;
            return 1;
        case VR_ALPHA:
            if (known == VR_TORQUE) *partial = k->inverse_inertia;
            else if (known == VR_THETA) *partial = -k->gravity_moment * cos(values[VR_THETA]) * k->inverse_inertia;
            else *partial = -k->damping * k->inverse_inertia;
            return 1;
        default:
            return 0;
    }
}
