/*
 * json_out.h: writing JSON strings, for the master's documents (the
 * statistics file of --stats-json, report.c; the monitor's API,
 * farm_monitor.c). One function: every string the master puts in JSON
 * goes through it, so every document is valid JSON whatever a worker
 * calls itself.
 */
#ifndef MASTER_JSON_OUT_H
#define MASTER_JSON_OUT_H

#include <stdio.h>

/* s as a JSON string, quotes included: '"', '\\' and control characters
 * escaped; bytes that are not well-formed UTF-8 (RFC 3629) become
 * U+FFFD. */
void json_out_string(FILE *out, const char *s);

#endif
