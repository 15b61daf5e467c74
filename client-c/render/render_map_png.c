/* render_map_png.c — the picture of a map as a PNG file, the one drawing
 * `meshcorr eval --out-png` and the web UI's job page (meshcorr-worker
 * --picture) both show: the source coloured through P beside the target
 * coloured by position (render_map_picture), the source turned to face as
 * its images P·X̃ do, with captions saying which side is which, which map
 * and how good it is. */
#include "render/render.h"
#include "map/bmap.h"
#include "metric/metric.h"
#include "viz/viz.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int render_map_png(const char *path, const mesh *S, const mesh *T, const bmap *P, const render_map_words *w,
                   int panel, char *err, size_t errsz)
{
    int rc = RENDER_ENOMEM;
    unsigned char *trgb = malloc(3 * (size_t)T->nv + 1), *srgb = malloc(3 * (size_t)S->nv + 1);
    unsigned char *kind = w->folds ? malloc((size_t)S->nf + 1) : NULL;
    double *img = malloc(sizeof(double) * 3 * (size_t)S->nv + 1);
    render_image *im = NULL, *pic = NULL;
    if (!trgb || !srgb || !img || (w->folds && (!kind || metric_fold_faces(S, T, P, kind) < 0)))
        goto fail;
    viz_position_colors(T, trgb);
    viz_pull_colors(P, T->f, trgb, srgb);
    bmap_apply(P, T->f, T->v, 3, img);
    if ((rc = render_map_picture(S, srgb, kind, img, T, trgb, panel, &pic)))
        goto fail;
    char src[600], tgt[600], map[600], quality[200], error[200] = "";
    snprintf(src, sizeof src, "source: %s", w->source);
    snprintf(tgt, sizeof tgt, "target: %s", w->target);
    snprintf(map, sizeof map, "map: %s", w->map);
    if (isfinite(w->flipped) && isfinite(w->collapsed))
        snprintf(quality, sizeof quality, "source triangles flipped %.2f %%, collapsed %.2f %%%s",
                 100 * w->flipped, 100 * w->collapsed, w->folds ? " (hatched)" : "");
    else
        snprintf(quality, sizeof quality, "source triangles flipped and collapsed: not known");
    if (w->gt_points > 0)
        snprintf(error, sizeof error, "geodesic error: mean %.4f of sqrt(area), %d points", w->gt_mean,
                 w->gt_points);
    render_caption cap = {{src, "coloured through the map"}, {tgt, "coloured by position"},
                          {map, quality, w->gt_points > 0 ? error : "top: the target's widest side; bottom: from behind",
                           w->gt_points > 0 ? "top: the target's widest side; bottom: from behind" : NULL}};
    if ((rc = render_captioned(pic, &cap, &im)))
        goto fail;
    rc = render_png_write(im, path, err, errsz);
    goto out;
fail:
    snprintf(err, errsz, "%s: %s", path, render_strerror(rc));
out:
    render_image_free(pic);
    render_image_free(im);
    free(img);
    free(kind);
    free(trgb);
    free(srgb);
    return rc;
}
