/* testfile.c — see testfile.h. */
#include "support/testfile.h"
#include "support/harness.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *testfile_write(const char *name, const void *data, size_t len)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", harness_tmpdir(), name);
    FILE *fp = fopen(path, "wb");
    CHECK(fp);
    CHECK(fwrite(data, 1, len, fp) == len);
    CHECK(fclose(fp) == 0);
    return path;
}

const char *testfile_text(const char *name, const char *text)
{
    return testfile_write(name, text, strlen(text));
}

unsigned char *testfile_read(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    CHECK(fp);
    CHECK(fseek(fp, 0, SEEK_END) == 0);
    long n = ftell(fp);
    CHECK(n >= 0);
    rewind(fp);
    unsigned char *b = malloc((size_t)n + 1);
    CHECK(b);
    CHECK(fread(b, 1, (size_t)n, fp) == (size_t)n);
    fclose(fp);
    *len = (size_t)n;
    return b;
}
