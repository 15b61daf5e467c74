/* spool.h — the spool directory contract between meshcorrd and
 * meshcorr-worker (workers/WORKER.md is its text): the names of the files in
 * <state-dir>/spool/<id>/, the worker's exit statuses and the descriptors
 * the local daemon hands the worker. The one place both sides take them
 * from. Names and numbers only. */
#ifndef SPOOL_H
#define SPOOL_H

/* files of spool/<id>/ */
#define SPOOL_JOB_FRAME     "job.frame"        /* the SUBMIT as accepted (daemon) */
#define SPOOL_RESULT_FRAME  "result.frame"     /* RESULT_OK (worker, atomically) */
#define SPOOL_ERROR_FRAME   "error.frame"      /* ERROR (worker, atomically) */
#define SPOOL_PROGRESS_FILE "progress.frames"  /* PROGRESS frames appended (Slurm worker without TCP) */
#define SPOOL_SECRET_FILE   "progress.secret"  /* the Slurm worker's progress secret (daemon, 0600) */
#define SPOOL_SLURM_OUT     "slurm.out"        /* the Slurm job's output */
#define SPOOL_WORKER_LOCK   "worker.lock"      /* flock held by the job's worker process (local daemon) */
#define SPOOL_PICTURE       "map.png"          /* the picture of a completed job's map (meshcorr-worker --picture, for the web) */
#define SPOOL_TMP_SUFFIX    ".tmp"             /* NAME.tmp, fsynced, renamed to NAME */

/* the worker's exit statuses */
#define SPOOL_EXIT_OK        0   /* result.frame written */
#define SPOOL_EXIT_JOB       1   /* error.frame written */
#define SPOOL_EXIT_USAGE     2   /* bad command line or job directory; no frame */
#define SPOOL_EXIT_CANCELLED 3   /* SIGTERM; error.frame holds CANCELLED */
#define SPOOL_EXIT_NO_ANSWER 4   /* neither frame could be written (disk full, I/O error): the
                                  * job has no answer and runs again */

/* descriptors the local daemon hands the worker */
#define SPOOL_PROGRESS_FD 3      /* --progress-fd: PROGRESS frames */
#define SPOOL_LOCK_FD     4      /* the locked worker.lock, kept open until the exit */

#endif
