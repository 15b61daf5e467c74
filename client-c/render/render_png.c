/* render_png.c — see render.h. An image to an 8-bit RGB PNG through
 * libpng's simplified API (no setjmp: errors come back as a message). */
#include "render/render.h"

#include <png.h>
#include <stdio.h>
#include <string.h>

int render_png_write(const render_image *im, const char *path, char *err, size_t errsz)
{
    png_image png;
    memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    png.width = (png_uint_32)im->w;
    png.height = (png_uint_32)im->h;
    png.format = PNG_FORMAT_RGB;
    if (!png_image_write_to_file(&png, path, 0, im->rgb, 3 * im->w, NULL)) {
        snprintf(err, errsz, "%s: %s (%s)", path, render_strerror(RENDER_EPNG), png.message);
        png_image_free(&png);
        return RENDER_EPNG;
    }
    return RENDER_OK;
}
