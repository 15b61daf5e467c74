/* testjson.h — checking that a command's output is JSON: a strict validator
 * (RFC 8259 grammar, one value) and nothing else. Test code only. */
#ifndef TESTJSON_H
#define TESTJSON_H

/* 1 when s is exactly one JSON value, surrounded by whitespace at most. */
int testjson_valid(const char *s);

#endif
