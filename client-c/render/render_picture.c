/* render_picture.c — see render.h. The picture of a map: the source
 * coloured through the map beside the target coloured by position, from
 * the front and from behind (a map that mirrors the shape shows the wrong
 * colours on one side at least). Each panel is drawn into its own image
 * and pasted, so that equal shapes in equal colours give equal panels,
 * pixel for pixel. */
#include "render/render.h"

#define RENDER_AZIMUTH 30.0      /* degrees about the screen's vertical */
#define RENDER_ELEVATION 20.0    /* degrees looking down */

static const unsigned char background[3] = {255, 255, 255};

/* The view v after the rotation R: rows of v·R. */
static render_view view_after(const render_view *v, const double R[3][3])
{
    render_view out;
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            out.r[i][k] = v->r[i][0] * R[0][k] + v->r[i][1] * R[1][k] + v->r[i][2] * R[2][k];
    return out;
}

int render_map_picture(const mesh *S, const unsigned char *srgb, const unsigned char *smark,
                       const double *simg, const mesh *T, const unsigned char *trgb, int px,
                       render_image **out)
{
    *out = NULL;
    if (px < 16 || px > RENDER_MAX_SIDE / 2)
        return RENDER_ESIZE;
    render_view front = render_view_widest(T, RENDER_AZIMUTH, RENDER_ELEVATION);
    render_view views[2][2];   /* [row][column] */
    double R[3][3];            /* turns the source to face as its images do */
    int rc = render_rotation_fit(S->v, simg, S->nv, R);
    if (rc)
        return rc;
    views[0][1] = front;
    views[1][1] = render_view_turned(&front, 180);
    for (int row = 0; row < 2; row++)
        views[row][0] = view_after(&views[row][1], R);
    render_image *im = render_image_new(2 * px, 2 * px, background);
    if (!im)
        return RENDER_ENOMEM;
    for (int row = 0; row < 2; row++)
        for (int col = 0; col < 2; col++) {
            render_image *panel = render_image_new(px, px, background);
            rc = !panel ? RENDER_ENOMEM
               : col == 0 ? render_mesh(S, srgb, smark, &views[row][0], panel)
                          : render_mesh(T, trgb, NULL, &views[row][1], panel);
            if (!rc)
                render_image_paste(im, panel, col * px, row * px);
            render_image_free(panel);
            if (rc) {
                render_image_free(im);
                return rc;
            }
        }
    *out = im;
    return RENDER_OK;
}
