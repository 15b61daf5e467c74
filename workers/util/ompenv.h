/* ompenv.h — makes OpenMP threads sleep instead of spin while they wait.
 *
 * libgomp spins at every barrier by default. When the machine is busier than
 * our thread count (a shared lab server, two jobs on two cores), a spinning
 * thread waits for a descheduled partner for a whole time slice: measured
 * here, 10 outer ECTM iterations on 381 -> 390 took 21.9 s with 2 spinning
 * threads under a load of 2, against 2.35 s with passive waiting. libgomp
 * reads OMP_WAIT_POLICY once, when it is loaded, so a program must set it
 * before it starts: ompenv_ensure_passive re-executes the program with
 * OMP_WAIT_POLICY=passive unless the user set the variable (their choice is
 * kept). Call it first thing in main(); it returns only when no re-exec was
 * needed or possible. */
#ifndef OMPENV_H
#define OMPENV_H

void ompenv_ensure_passive(char **argv);

#endif
