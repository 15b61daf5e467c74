/* corr__pieces.h — internal (corr__): a job whose meshes are in pieces
 * that the landmarks pair one to one (the input repair keeps such pieces,
 * corr_fix_open) runs pair by pair: corr_run splits the input into one
 * input per pair (corr__pieces_open), runs each, and joins the maps
 * (corr__pieces_join). */
#ifndef CORR__PIECES_H
#define CORR__PIECES_H
#include "corr/corr.h"

typedef struct corr__piece {
    mesh *S, *T;               /* the pair's pieces                         */
    int *sv, *tv;              /* their vertices' indices in in's meshes    */
    int *sf, *tf;              /* their faces' indices in in's meshes       */
    lmk_set L;                 /* the landmarks on the pair                 */
    corr_input in;             /* the pair's job                            */
} corr__piece;

typedef struct corr__pieces {
    int n;                     /* pairs; 0: both meshes are in one piece    */
    corr__piece *p;
} corr__pieces;

/* Splits in into its pairs. n = 0 (nothing else done) when neither mesh
 * is in more than one piece, or when in has no landmarks or has a given
 * map (then corr_run's check refuses pieces as before). KIND_EMESH when a
 * piece is left unpaired (naming the counts), KIND_ENOMEM. */
int corr__pieces_open(const corr_input *in, corr__pieces *pc, char *err, size_t errsz);
/* The pairs' results (res[k] for pair k) as one result on in's meshes;
 * last: the last pair's report. KIND_ENOMEM. */
int corr__pieces_join(const corr_input *in, const corr__pieces *pc, const ectm_result *res,
                      ectm_result *out, char *err, size_t errsz);
void corr__pieces_close(corr__pieces *pc);

#endif
