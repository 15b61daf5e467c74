/* render.h — offscreen pictures of meshes for a person to open anywhere: a
 * small z-buffered rasteriser (orthographic, flat two-sided Lambert shading
 * of per-vertex colours, supersampled) and a PNG writer (libpng). This is
 * the CLI's concern, not the engine's: the module is linked into `meshcorr`,
 * into `meshcorr-worker` (its --picture for the web UI) and the tests only,
 * never into libmeshcorr, so libpng stays out of the client library's
 * dependencies.
 *
 * Images are h rows of w RGB pixels (3 bytes each), top row first.
 * Ownership: render_image_new and render_map_picture return an image the
 * caller frees with render_image_free (NULL is accepted). Errors are
 * negative RENDER_E* codes; render_png_write puts the detail (file, libpng's
 * message) into the caller's err buffer. */
#ifndef RENDER_H
#define RENDER_H
#include <stddef.h>
#include "map/bmap.h"
#include "mesh/mesh.h"
#include "util/errlist.h"

#define RENDER_MAX_SIDE 8192      /* pixels per image side */
#define RENDER_SUPERSAMPLE 3      /* samples per pixel side (3 x 3 averaged) */

#define RENDER_ERRORS(X)                                                    \
    X(RENDER_OK,      0, "ok")                                              \
    X(RENDER_ENOMEM, -1, "out of memory")                                   \
    X(RENDER_ESIZE,  -2, "image size out of range")                         \
    X(RENDER_EEIGEN, -3, "eigen-solver (LAPACK) failed")                    \
    X(RENDER_EPNG,   -4, "cannot write the PNG file")

ERRLIST_ENUM(render, RENDER_ERRORS);
const char *render_strerror(int code);

typedef struct render_image {
    int w, h;             /* pixels */
    unsigned char *rgb;   /* h by w by 3 bytes, top row first */
} render_image;

/* An image of w by h pixels (1..RENDER_MAX_SIDE) filled with bg (3 bytes). */
render_image *render_image_new(int w, int h, const unsigned char bg[3]);
void render_image_free(render_image *im);
/* Copies src into dst with src's top-left pixel at (x, y); what falls
 * outside dst is cut off. */
void render_image_paste(render_image *dst, const render_image *src, int x, int y);

/* A view: an orthonormal, right-handed rotation whose rows are the screen's
 * x axis (right), y axis (up) and the direction towards the viewer. */
typedef struct render_view {
    double r[3][3];
} render_view;

/* The view of m's widest side: screen x along the world axis (x, y or z)
 * of m's greatest extent, screen y along the one of the middle extent,
 * both in their positive directions (a shape modelled upright along its
 * middle axis stays upright), looking along the third; then turned by az
 * degrees about the screen's vertical and el degrees about its horizontal
 * (an oblique look, from above for el > 0). */
render_view render_view_widest(const mesh *m, double az, double el);
/* v turned by deg degrees about its own screen vertical (180: from behind). */
render_view render_view_turned(const render_view *v, double deg);

/* R: the rotation that best turns the points X onto the points Y (n by 3
 * each, point i onto point i), both about their centroids: it minimises
 * sum |R (x_i - mean x) - (y_i - mean y)|^2 over proper rotations (det 1).
 * A result within 1e-12 of the identity is made exactly the identity.
 * RENDER_EEIGEN when LAPACK fails. */
int render_rotation_fit(const double *X, const double *Y, int n, double R[3][3]);

/* Draws m seen through view into im: centred and scaled so that its
 * projection fills im but a margin, z-buffered, each face flat-shaded by a
 * light over the viewer's shoulder (both sides lit alike: open or
 * inside-out meshes still show), its colour interpolated from rgb (nv by 3
 * bytes) at the corners; faces with mark[t] != 0 are hatched with dark
 * stripes (mark NULL: none). Pixels m does not cover keep im's colour.
 * The result depends only on m, rgb, mark, view and im's size and colours,
 * so equal inputs give equal pixels. Returns 0 or RENDER_ENOMEM. */
int render_mesh(const mesh *m, const unsigned char *rgb, const unsigned char *mark,
                const render_view *view, render_image *im);

/* The picture of a map from S to T: 2 by 2 panels of px by px pixels
 * (px in 16..RENDER_MAX_SIDE/2). Left column the source S in its colours
 * srgb (the target's colours pulled through the map), its faces with
 * smark[t] != 0 hatched (NULL: none); right column the target T in trgb.
 * Top row: the view of T's widest side (render_view_widest, turned 30
 * degrees and looking 20 degrees down); bottom row: the same view from
 * behind. The source is first turned by the rotation that best takes its
 * vertices onto simg (nv by 3: their images on T, e.g. P·X̃), so that the
 * two shapes face the same way even when their files use other frames;
 * each is centred and scaled in its own panel. A good map shows the same
 * colour at the same place left and right. */
int render_map_picture(const mesh *S, const unsigned char *srgb, const unsigned char *smark,
                       const double *simg, const mesh *T, const unsigned char *trgb, int px,
                       render_image **out);

/* Text in a 5 by 9 pixel font (printable ASCII; other bytes show as '?'),
 * each font pixel a scale by scale block of rgb, the top-left of the first
 * glyph at (x, y); what falls outside im is cut off. Returns the width
 * drawn, as render_text_width. */
#define RENDER_FONT_W 5           /* glyph pixels across */
#define RENDER_FONT_H 9           /* glyph pixels down (2 below the baseline) */
#define RENDER_FONT_ADVANCE 6     /* font pixels from a glyph to the next */
#define RENDER_FONT_LINE 11       /* font pixels from a line of text to the next */
int render_text(render_image *im, int x, int y, int scale, const unsigned char rgb[3], const char *text);
/* Pixels across that text takes at scale (no blank after the last glyph). */
int render_text_width(const char *text, int scale);

/* The words around a map picture (render_map_picture): two lines above
 * each column (what the mesh is, how it is coloured) and up to
 * RENDER_CAPTION_LINES below (which map, its quality); NULL or "" lines
 * stay blank. A line too long for its place ends in "...". */
#define RENDER_CAPTION_LINES 4
#define RENDER_CAPTION_MAX 256    /* characters of one line drawn at most */
typedef struct render_caption {
    const char *source[2];        /* above the left column */
    const char *target[2];        /* above the right column */
    const char *below[RENDER_CAPTION_LINES];
} render_caption;
/* pic with a band of render_caption_top(pic->w) pixels above it and one of
 * render_caption_bottom(pic->w) below (text at 1 font pixel per pixel, 2
 * from 800 pixels across), on white: a new image in *out. RENDER_ESIZE when
 * the result would be over RENDER_MAX_SIDE, RENDER_ENOMEM. */
int render_captioned(const render_image *pic, const render_caption *c, render_image **out);
int render_caption_top(int w);
int render_caption_bottom(int w);

/* Writes im as an 8-bit RGB PNG. RENDER_EPNG with the file and libpng's
 * message in err. */
int render_png_write(const render_image *im, const char *path, char *err, size_t errsz);

/* What a map picture's captions say (render_map_png): the names of the
 * source, target and map, the map's flipped and collapsed fractions (NaN:
 * not known), and, gt_points > 0, its mean geodesic error; folds: P's
 * flipped and collapsed source faces are hatched. */

typedef struct render_map_words {
    const char *source, *target, *map;
    double flipped, collapsed, gt_mean;
    int gt_points, folds;
} render_map_words;
/* path: S coloured through P beside T coloured by position
 * (render_map_picture with panel pixels per panel side), captioned
 * (render_captioned), as a PNG. 0, or a RENDER_E* code with the file and
 * why in err. */
int render_map_png(const char *path, const mesh *S, const mesh *T, const bmap *P, const render_map_words *w,
                   int panel, char *err, size_t errsz);

#endif
