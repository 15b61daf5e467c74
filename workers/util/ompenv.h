/* ompenv.h — makes OpenMP threads sleep instead of spin while they wait.
 *
 * libgomp spins at every barrier by default. When the machine is busier than
 * our thread count (a shared lab server, two jobs on two cores), a spinning
 * thread waits for a descheduled partner for a whole time slice
 * (docs/decisions.md, "OpenMP threads wait passively"). libgomp
 * reads OMP_WAIT_POLICY once, when it is loaded, so a program must set it
 * before it starts: ompenv_ensure_passive re-executes the program with
 * OMP_WAIT_POLICY=passive unless the user set the variable (their choice is
 * kept). Call it first thing in main(); it returns only when no re-exec was
 * needed or possible. */
#ifndef OMPENV_H
#define OMPENV_H

void ompenv_ensure_passive(char **argv);

/* Sets OMP_WAIT_POLICY=passive in the environment unless the user set it;
 * 1 when it set it. For a program that runs no OpenMP itself but starts
 * programs that do (meshcorrd's workers inherit it and skip their re-exec). */
int ompenv_set_passive(void);

/* Threads for a job whose two meshes have `vertices` vertices together:
 * requested when > 0 (the user's choice, kept), else one thread per
 * OMPENV_VERTICES_PER_THREAD vertices, at least 1 and at most the cores.
 * A small job's passes over its elements take microseconds, less than
 * waking a second thread at each of their barriers costs. ompenv_threads.c;
 * the caller passes the result to omp_set_num_threads
 * and to the engines' thread parameters before the first parallel region. */
#define OMPENV_VERTICES_PER_THREAD 2000
int ompenv_threads_for(int vertices, int requested);

#endif
