/* render_caption.c — see render.h. A map picture with words around it:
 * above each column what it shows (which mesh, how it is coloured), below
 * the picture which map and its quality, so that a picture shown on its
 * own still says what it is. Band heights depend only on the picture's
 * width, so equal pictures give equal layouts. */
#include "render/render.h"

#include <stdio.h>
#include <string.h>

#define RENDER_CAPTION_MARGIN 4    /* font pixels around the text of a band */
#define RENDER_CAPTION_PER_SCALE 400   /* picture pixels per step of the text scale */

static const unsigned char ink[3] = {20, 20, 20}, grey[3] = {90, 90, 90}, paper[3] = {255, 255, 255};

/* Font pixels are scale by scale picture pixels: 2 on eval's 800-pixel
 * picture, 1 on small ones. */
static int scale_of(int w)
{
    int s = w / RENDER_CAPTION_PER_SCALE;
    return s < 1 ? 1 : s;
}

int render_caption_top(int w)
{
    return scale_of(w) * (2 * RENDER_FONT_LINE + 2 * RENDER_CAPTION_MARGIN);
}

int render_caption_bottom(int w)
{
    return scale_of(w) * (RENDER_CAPTION_LINES * RENDER_FONT_LINE + 2 * RENDER_CAPTION_MARGIN);
}

/* text at (x, y), cut to width pixels with "..." at its end. */
static void line_at(render_image *im, int x, int y, int width, int s, const unsigned char rgb[3], const char *text)
{
    if (!text || !*text)
        return;
    int fit = (width + s) / (RENDER_FONT_ADVANCE * s);
    char buf[RENDER_CAPTION_MAX + 1];
    size_t n = strlen(text);
    if (fit < 4 || fit > RENDER_CAPTION_MAX)
        fit = fit < 4 ? 4 : RENDER_CAPTION_MAX;
    if (n > (size_t)fit)
        snprintf(buf, sizeof buf, "%.*s...", fit - 3, text);
    else
        snprintf(buf, sizeof buf, "%s", text);
    render_text(im, x, y, s, rgb, buf);
}

int render_captioned(const render_image *pic, const render_caption *c, render_image **out)
{
    *out = NULL;
    int s = scale_of(pic->w), top = render_caption_top(pic->w), bottom = render_caption_bottom(pic->w);
    int m = RENDER_CAPTION_MARGIN * s, line = RENDER_FONT_LINE * s;
    if (pic->h + top + bottom > RENDER_MAX_SIDE)
        return RENDER_ESIZE;
    render_image *im = render_image_new(pic->w, pic->h + top + bottom, paper);
    if (!im)
        return RENDER_ENOMEM;
    render_image_paste(im, pic, 0, top);
    int colw = pic->w / 2;
    for (int k = 0; k < 2; k++) {
        line_at(im, m, m + k * line, colw - 2 * m, s, k ? grey : ink, c->source[k]);
        line_at(im, colw + m, m + k * line, pic->w - colw - 2 * m, s, k ? grey : ink, c->target[k]);
    }
    for (int k = 0; k < RENDER_CAPTION_LINES; k++)
        line_at(im, m, top + pic->h + m + k * line, pic->w - 2 * m, s, k ? grey : ink, c->below[k]);
    *out = im;
    return RENDER_OK;
}
