/*
 * monitor_page.h: the live monitor's page (master/monitor_page/: one HTML
 * file, its script and its style), embedded in aafarm-master at build time
 * by monitor_page/embed.cmake as byte arrays: no files to install, no CDN,
 * no build step for the script.
 */
#ifndef MASTER_MONITOR_PAGE_H
#define MASTER_MONITOR_PAGE_H

#include <stddef.h>

typedef struct monitor_page_file {
    const char *path;              /* "/index.html", "/monitor.js", ... */
    const char *mime;              /* its Content-Type */
    const unsigned char *data;
    size_t len;
} monitor_page_file;

extern const monitor_page_file monitor_page_files[];
extern const int monitor_page_nfiles;

#endif
