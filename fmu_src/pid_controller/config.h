#ifndef CONFIG_H
#define CONFIG_H

/* The controller's one state is the integral of the angle error. */
#define N_STATES 1

typedef struct {
    double setpoint;
    double proportional_gain;
    double integral_gain;
    double derivative_gain;
} ModelCoefficients;

#endif
