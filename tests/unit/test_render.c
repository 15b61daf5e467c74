/* test_render.c — the pictures of client-c/render: the z-buffer keeps the
 * nearer face, marked faces hatched, the fitted rotation, the picture of a map (the identity of
 * a mesh onto itself gives two equal halves pixel for pixel, a mirrored
 * map does not), the PNG read back with libpng, text in the embedded font
 * and the captions around a picture, and the same through `meshcorr eval
 * --out-png`, whose captions say which side is which and which map. */
#include "support/harness.h"
#include "support/testmesh.h"
#include "map/bmap.h"
#include "render/render.h"
#include "viz/viz.h"

#include <png.h>
#include <string.h>
#include <sys/wait.h>

#define PANEL 120

static const unsigned char white[3] = {255, 255, 255};

/* A closed shape with no mirror symmetry: an icosphere stretched, sheared
 * and bent. */
static mesh *shape(void)
{
    mesh *m = testmesh_icosphere(3);
    CHECK(m);
    for (int i = 0; i < m->nv; i++) {
        double *p = m->v + 3 * i, x = p[0], y = p[1], z = p[2];
        p[0] = 1.6 * x + 0.4 * y * y;
        p[1] = y + 0.3 * x * z;
        p[2] = 0.6 * z + 0.25 * x;
    }
    return m;
}

/* The map sending each vertex of m to itself, as a corner of its first
 * face with weights (1, 0, 0) in that corner's place. */
static bmap *identity_map(const mesh *m)
{
    bmap *P = bmap_new(m->nv, m->nv);
    CHECK(P);
    for (int i = 0; i < m->nv; i++)
        P->face[i] = -1;
    for (int t = 0; t < m->nf; t++)
        for (int q = 0; q < 3; q++) {
            int v = m->f[3 * t + q];
            if (P->face[v] < 0) {
                P->face[v] = t;
                P->w[3 * v + q] = 1;
            }
        }
    for (int i = 0; i < m->nv; i++)
        CHECK(P->face[i] >= 0);
    return P;
}

/* The picture of P from S to T as meshcorr eval draws it. */
static render_image *picture(const mesh *S, const mesh *T, const bmap *P)
{
    unsigned char *trgb = malloc(3 * (size_t)T->nv), *srgb = malloc(3 * (size_t)S->nv);
    double *img = malloc(sizeof(double) * 3 * (size_t)S->nv);
    CHECK(trgb && srgb && img);
    viz_position_colors(T, trgb);
    viz_pull_colors(P, T->f, trgb, srgb);
    bmap_apply(P, T->f, T->v, 3, img);
    render_image *im = NULL;
    CHECK_INT(render_map_picture(S, srgb, NULL, img, T, trgb, PANEL, &im), RENDER_OK);
    free(trgb);
    free(srgb);
    free(img);
    return im;
}

/* Pixels where the left half differs from the right half. */
static long halves_differ(const unsigned char *rgb, int w, int h)
{
    long n = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w / 2; x++)
            n += memcmp(rgb + 3 * ((size_t)y * w + x), rgb + 3 * ((size_t)y * w + x + w / 2), 3) != 0;
    return n;
}

/* Pixels not white in the panel whose top-left corner is (x0, y0). */
static long drawn(const render_image *im, int x0, int y0, int side)
{
    long n = 0;
    for (int y = y0; y < y0 + side; y++)
        for (int x = x0; x < x0 + side; x++)
            n += memcmp(im->rgb + 3 * ((size_t)y * im->w + x), white, 3) != 0;
    return n;
}

/* A PNG read back with libpng as 8-bit RGB; *w by *h pixels. */
static unsigned char *png_read(const char *path, int *w, int *h)
{
    png_image png;
    memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, path))
        FAILF("%s: %s", path, png.message);
    png.format = PNG_FORMAT_RGB;
    unsigned char *rgb = malloc(PNG_IMAGE_SIZE(png));
    CHECK(rgb);
    if (!png_image_finish_read(&png, NULL, rgb, 0, NULL))
        FAILF("%s: %s", path, png.message);
    *w = (int)png.width;
    *h = (int)png.height;
    return rgb;
}

TEST(nearer_face_hides_the_farther_one_whichever_comes_first)
{
    /* two triangles over the same square, near (z = 1) and far (z = 0) */
    mesh *m = mesh_new(6, 2);
    const double v[18] = {0, 0, 1, 1, 0, 1, 0, 1, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    memcpy(m->v, v, sizeof v);
    const unsigned char rgb[18] = {0, 200, 0, 0, 200, 0, 0, 200, 0, 200, 0, 0, 200, 0, 0, 200, 0, 0};
    render_view view = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    for (int order = 0; order < 2; order++) {
        int near[3] = {0, 1, 2}, far[3] = {3, 4, 5};
        memcpy(m->f + 3 * order, near, sizeof near);
        memcpy(m->f + 3 * (1 - order), far, sizeof far);
        render_image *im = render_image_new(40, 40, white);
        CHECK_INT(render_mesh(m, rgb, NULL, &view, im), RENDER_OK);
        /* inside the triangle (lower left of the picture: y is up): green */
        const unsigned char *p = im->rgb + 3 * (30 * 40 + 10);
        CHECK(p[1] > 0 && p[0] == 0 && p[2] == 0);
        /* outside it (upper right corner): the background */
        CHECK(memcmp(im->rgb + 3 * (2 * 40 + 37), white, 3) == 0);
        render_image_free(im);
    }
    mesh_free(m);
}

TEST(marked_faces_are_hatched_and_only_they)
{
    mesh *m = shape();
    unsigned char *rgb = malloc(3 * (size_t)m->nv), *mark = calloc((size_t)m->nf, 1);
    CHECK(rgb && mark);
    viz_position_colors(m, rgb);
    render_view view = render_view_widest(m, 30, 20);
    long dark[2];
    for (int marked = 0; marked < 2; marked++) {
        for (int t = 0; t < m->nf; t++)
            mark[t] = marked && t % 2 == 0;   /* every other face */
        render_image *im = render_image_new(PANEL, PANEL, white);
        CHECK_INT(render_mesh(m, rgb, mark, &view, im), RENDER_OK);
        dark[marked] = 0;
        for (int p = 0; p < PANEL * PANEL; p++)
            dark[marked] += im->rgb[3 * p] == 20 && im->rgb[3 * p + 1] == 20 && im->rgb[3 * p + 2] == 20;
        render_image_free(im);
    }
    CHECK_INT(dark[0], 0);
    CHECK(dark[1] > PANEL * PANEL / 50);
    free(rgb);
    free(mark);
    mesh_free(m);
}

TEST(rotation_fit_recovers_a_rotation_and_gives_the_identity_exactly)
{
    mesh *m = shape();
    double c = cos(0.7), s = sin(0.7), Rt[3][3] = {{c, -s, 0}, {s, c, 0}, {0, 0, 1}}, R[3][3];
    double *Y = malloc(sizeof(double) * 3 * m->nv);
    for (int i = 0; i < m->nv; i++)
        for (int a = 0; a < 3; a++)
            Y[3 * i + a] = Rt[a][0] * m->v[3 * i] + Rt[a][1] * m->v[3 * i + 1] +
                           Rt[a][2] * m->v[3 * i + 2] + 5.0 * (a + 1);
    CHECK_INT(render_rotation_fit(m->v, Y, m->nv, R), RENDER_OK);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            CHECK_NEAR(R[a][b], Rt[a][b], 1e-9);
    CHECK_INT(render_rotation_fit(m->v, m->v, m->nv, R), RENDER_OK);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            CHECK(R[a][b] == (a == b));
    free(Y);
    mesh_free(m);
}

TEST(identity_map_gives_equal_halves_pixel_for_pixel)
{
    mesh *T = shape(), *S = mesh_copy(T);
    bmap *P = identity_map(T);
    render_image *im = picture(S, T, P);
    CHECK_INT(im->w, 2 * PANEL);
    CHECK_INT(im->h, 2 * PANEL);
    /* every panel shows the shape, and big */
    for (int r = 0; r < 2; r++)
        for (int c = 0; c < 2; c++)
            CHECK(drawn(im, c * PANEL, r * PANEL, PANEL) > PANEL * PANEL / 5);
    CHECK_INT(halves_differ(im->rgb, im->w, im->h), 0);
    /* front and back are different pictures */
    CHECK(memcmp(im->rgb, im->rgb + 3 * (size_t)PANEL * im->w, 3 * (size_t)PANEL * im->w) != 0);
    render_image_free(im);
    bmap_free(P);
    mesh_free(S);
    mesh_free(T);
}

TEST(mirrored_map_gives_halves_that_differ)
{
    mesh *T = shape(), *S = testmesh_mirrored(T);
    bmap *P = identity_map(T);   /* vertex i of the mirror image -> vertex i */
    render_image *im = picture(S, T, P);
    long covered = drawn(im, PANEL, 0, PANEL) + drawn(im, PANEL, PANEL, PANEL);
    CHECK(halves_differ(im->rgb, im->w, im->h) > covered / 4);
    render_image_free(im);
    bmap_free(P);
    mesh_free(S);
    mesh_free(T);
}

TEST(png_reads_back_with_libpng_at_its_size_and_pixels)
{
    mesh *T = shape(), *S = mesh_copy(T);
    bmap *P = identity_map(T);
    render_image *im = picture(S, T, P);
    char path[600], err[1024];
    snprintf(path, sizeof path, "%s/map.png", harness_tmpdir());
    CHECK_INT(render_png_write(im, path, err, sizeof err), RENDER_OK);
    int w, h;
    unsigned char *rgb = png_read(path, &w, &h);
    CHECK_INT(w, 2 * PANEL);
    CHECK_INT(h, 2 * PANEL);
    CHECK(memcmp(rgb, im->rgb, 3 * (size_t)w * h) == 0);
    /* a folder that does not exist: refused, naming the file */
    snprintf(path, sizeof path, "%s/no/such/dir/map.png", harness_tmpdir());
    CHECK_INT(render_png_write(im, path, err, sizeof err), RENDER_EPNG);
    CHECK_STR_HAS(err, "no/such/dir/map.png");
    free(rgb);
    render_image_free(im);
    bmap_free(P);
    mesh_free(S);
    mesh_free(T);
}

/* Runs cmd; its output in out; returns its exit code. */
static int run(const char *cmd, char *out, size_t outsz)
{
    FILE *p = popen(cmd, "r");
    CHECK(p);
    size_t n = fread(out, 1, outsz - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* meshcorr eval SOURCE TARGET P.map --out-png FILE; returns its exit code. */
static int eval_png(const char *src, const char *tgt, const char *map, const char *png, char *out,
                    size_t outsz)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s --out-png %s 2>&1", src, tgt, map, png);
    return run(cmd, out, outsz);
}

/* The pixels of text drawn alone at (x, y) on white, as the w by h region
 * of rgb (stride w_full) whose top-left is (0, 0) of that region: the
 * number that differ. */
static long text_differs(const unsigned char *rgb, int w_full, int x0, int y0, int w, int h, int x, int y,
                         int scale, const unsigned char ink[3], const char *text)
{
    render_image *want = render_image_new(w, h, white);
    CHECK(want);
    render_text(want, x, y, scale, ink, text);
    long n = 0;
    for (int r = 0; r < h; r++)
        for (int c = 0; c < w; c++)
            n += memcmp(rgb + 3 * ((size_t)(y0 + r) * w_full + (size_t)(x0 + c)),
                        want->rgb + 3 * ((size_t)r * w + (size_t)c), 3) != 0;
    render_image_free(want);
    return n;
}

/* A glyph lands where and as wide as render_text_width says, each font
 * pixel a scale by scale block; a byte outside printable ASCII draws as
 * '?'; text past the image's edge is cut, not written out of bounds. */
TEST(text_draws_glyphs_in_place_scaled_and_clipped)
{
    static const unsigned char ink[3] = {0, 0, 0};
    render_image *im = render_image_new(40, 30, white);
    CHECK(im);
    CHECK_INT(render_text(im, 3, 2, 2, ink, "T"), render_text_width("T", 2));
    CHECK_INT(render_text_width("T", 2), RENDER_FONT_W * 2);
    CHECK_INT(render_text_width("ab", 2), 2 * RENDER_FONT_ADVANCE * 2 - 2);
    CHECK_INT(render_text_width("", 3), 0);
    /* the bar of the T: its first two rows, ten pixels across */
    for (int y = 0; y < 30; y++)
        for (int x = 0; x < 40; x++) {
            int bar = y >= 2 && y < 4 && x >= 3 && x < 13;
            int stem = y >= 2 && y < 2 + 2 * 7 && x >= 7 && x < 9;
            int inked = memcmp(im->rgb + 3 * ((size_t)y * 40 + x), ink, 3) == 0;
            if (inked != (bar || stem))
                FAILF("pixel (%d, %d) is %s", x, y, inked ? "inked" : "blank");
        }
    render_image *a = render_image_new(40, 30, white), *b = render_image_new(40, 30, white);
    render_text(a, 0, 0, 1, ink, "\xc3\xa9");
    render_text(b, 0, 0, 1, ink, "??");
    CHECK(memcmp(a->rgb, b->rgb, 3 * 40 * 30) == 0);
    render_text(a, 30, 25, 4, ink, "WWWW");          /* mostly outside: clipped */
    render_image_free(a);
    render_image_free(b);
    render_image_free(im);
}

/* The captioned picture is the picture, unchanged, between a band above
 * (each column's two lines, in place) and a band below (a line per entry;
 * an entry left NULL stays blank); a line too long ends in "...". */
TEST(captions_frame_the_picture_unchanged_and_write_each_line_in_place)
{
    mesh *S = shape();
    bmap *P = identity_map(S);
    render_image *pic = picture(S, S, P), *im = NULL;
    char longer[400];
    memset(longer, 'x', sizeof longer - 1);
    longer[sizeof longer - 1] = '\0';
    render_caption c = {{"source: a.off", "through the map"}, {"target: b.off", "by position"},
                        {"map: p.map", longer, NULL, NULL}};
    CHECK_INT(render_captioned(pic, &c, &im), RENDER_OK);
    int top = render_caption_top(pic->w), bottom = render_caption_bottom(pic->w);
    CHECK(top > 0 && bottom > 0);
    CHECK_INT(im->w, pic->w);
    CHECK_INT(im->h, pic->h + top + bottom);
    CHECK(memcmp(im->rgb + 3 * (size_t)top * im->w, pic->rgb, 3 * (size_t)pic->w * pic->h) == 0);
    static const unsigned char ink[3] = {20, 20, 20}, grey[3] = {90, 90, 90};
    int half = pic->w / 2, line = RENDER_FONT_LINE, m = 4;   /* a 240-pixel picture: scale 1 */
    /* above: each column's title, then its second line */
    CHECK_INT(text_differs(im->rgb, im->w, 0, 0, half, m + line, m, m, 1, ink, "source: a.off"), 0);
    CHECK(text_differs(im->rgb, im->w, 0, 0, half, m + line, m, m, 1, ink, "source: b.off") > 0);
    CHECK_INT(text_differs(im->rgb, im->w, 0, m + line, half, line, m, 0, 1, grey, "through the map"), 0);
    CHECK_INT(text_differs(im->rgb, im->w, half, 0, half, m + line, m, m, 1, ink, "target: b.off"), 0);
    CHECK_INT(text_differs(im->rgb, im->w, half, m + line, half, line, m, 0, 1, grey, "by position"), 0);
    /* below: the map's line, the long one cut to the width with "...",
     * and two blank lines */
    int y0 = top + pic->h + m;
    CHECK_INT(text_differs(im->rgb, im->w, 0, y0, im->w, line, m, 0, 1, ink, "map: p.map"), 0);
    int fit = (im->w - 2 * m + 1) / RENDER_FONT_ADVANCE;
    char cut[400];
    snprintf(cut, sizeof cut, "%.*s...", fit - 3, longer);
    CHECK_INT(text_differs(im->rgb, im->w, 0, y0 + line, im->w, line, m, 0, 1, grey, cut), 0);
    CHECK_INT(text_differs(im->rgb, im->w, 0, y0 + 2 * line, im->w, 2 * line, 0, 0, 1, grey, ""), 0);
    render_image_free(im);
    render_image_free(pic);
    bmap_free(P);
    mesh_free(S);
}

TEST(eval_out_png_of_identity_and_mirrored_maps)
{
    mesh *T = shape(), *M = testmesh_mirrored(T);
    bmap *P = identity_map(T);
    const char *dir = harness_tmpdir();
    char t[600], m[600], map[600], png[600], err[1024], out[8192], cmd[4096];
    snprintf(t, sizeof t, "%s/shape.off", dir);
    snprintf(m, sizeof m, "%s/mirror.off", dir);
    snprintf(map, sizeof map, "%s/id.map", dir);
    snprintf(png, sizeof png, "%s/id.png", dir);
    CHECK_INT(mesh_write(t, T, err, sizeof err), 0);
    CHECK_INT(mesh_write(m, M, err, sizeof err), 0);
    CHECK_INT(bmap_write(map, P, NULL, err, sizeof err), 0);
    CHECK_INT(eval_png(t, t, map, png, out, sizeof out), 0);
    int w, h, top = render_caption_top(800), bottom = render_caption_bottom(800);
    unsigned char *rgb = png_read(png, &w, &h);
    CHECK_INT(w, 800);
    CHECK_INT(h, 800 + top + bottom);
    CHECK_INT(halves_differ(rgb + 3 * (size_t)top * w, w, 800), 0);     /* the picture's halves */
    /* the captions: which side is which, which map, its quality (scale 2
     * on the 800-pixel picture, margins of 4 font pixels) */
    static const unsigned char ink[3] = {20, 20, 20}, grey[3] = {90, 90, 90};
    int line = 2 * RENDER_FONT_LINE;
    CHECK_INT(text_differs(rgb, w, 0, 0, 400, line + 8, 8, 8, 2, ink, "source: shape.off"), 0);
    CHECK_INT(text_differs(rgb, w, 0, 8 + line, 400, line, 8, 0, 2, grey, "coloured through the map"), 0);
    CHECK_INT(text_differs(rgb, w, 400, 0, 400, line + 8, 8, 8, 2, ink, "target: shape.off"), 0);
    CHECK_INT(text_differs(rgb, w, 400, 8 + line, 400, line, 8, 0, 2, grey, "coloured by position"), 0);
    CHECK_INT(text_differs(rgb, w, 0, top + 800 + 8, 800, line, 8, 0, 2, ink, "map: id.map"), 0);
    CHECK_INT(text_differs(rgb, w, 0, top + 800 + 8 + line, 800, line, 8, 0, 2, grey,
                           "source triangles flipped 0.00 %, collapsed 0.00 %"), 0);
    free(rgb);
    CHECK_INT(eval_png(m, t, map, png, out, sizeof out), 0);
    rgb = png_read(png, &w, &h);
    CHECK(halves_differ(rgb + 3 * (size_t)top * w, w, 800) > 10000);
    free(rgb);
    snprintf(cmd, sizeof cmd, "build/meshcorr eval %s %s %s --mark-folds 2>&1", t, t, map);
    CHECK_INT(run(cmd, out, sizeof out), 2);
    CHECK_STR_HAS(out, "--mark-folds goes with --out-png");
    snprintf(png, sizeof png, "%s/no/such/dir/id.png", dir);
    CHECK_INT(eval_png(t, t, map, png, out, sizeof out), 2);       /* refused before the work */
    CHECK_STR_HAS(out, "no/such/dir/id.png");
    bmap_free(P);
    mesh_free(M);
    mesh_free(T);
}
