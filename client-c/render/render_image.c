/* render_image.c — see render.h. The RGB image type, pasting one image into
 * another, and the module's error messages. */
#include "render/render.h"

#include <stdlib.h>
#include <string.h>

const char *render_strerror(int code)
{
    switch (code) { RENDER_ERRORS(ERRLIST_CASE) }
    return "unknown render error";
}

render_image *render_image_new(int w, int h, const unsigned char bg[3])
{
    if (w < 1 || h < 1 || w > RENDER_MAX_SIDE || h > RENDER_MAX_SIDE)
        return NULL;
    render_image *im = malloc(sizeof *im);
    if (!im)
        return NULL;
    im->w = w;
    im->h = h;
    if (!(im->rgb = malloc(3 * (size_t)w * (size_t)h))) {
        free(im);
        return NULL;
    }
    for (size_t p = 0; p < (size_t)w * (size_t)h; p++)
        memcpy(im->rgb + 3 * p, bg, 3);
    return im;
}

void render_image_free(render_image *im)
{
    if (!im)
        return;
    free(im->rgb);
    free(im);
}

void render_image_paste(render_image *dst, const render_image *src, int x, int y)
{
    int x0 = x < 0 ? -x : 0, x1 = src->w < dst->w - x ? src->w : dst->w - x;
    if (x1 <= x0)
        return;
    for (int r = 0; r < src->h; r++) {
        int dr = y + r;
        if (dr < 0 || dr >= dst->h)
            continue;
        memcpy(dst->rgb + 3 * ((size_t)dr * (size_t)dst->w + (size_t)(x + x0)),
               src->rgb + 3 * ((size_t)r * (size_t)src->w + (size_t)x0), 3 * (size_t)(x1 - x0));
    }
}
