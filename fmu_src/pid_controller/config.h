#ifndef CONFIG_H
#define CONFIG_H

/* The model's traits, which the FMI plumbing (fmu_src/src/) reads: the controller's one state is
   the integral of the angle error, it has no events and all its variables are Float64. */
#define N_STATES 1
#define HAS_EVENTS 0
#define FLOAT64_ONLY 1

typedef struct {
    double setpoint;
    double proportional_gain;
    double integral_gain;
    double derivative_gain;
} ModelCoefficients;

#endif
