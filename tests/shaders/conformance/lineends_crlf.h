/* CR-LF line ends, as files from Windows tools have */
#ifndef LINEENDS_CRLF_H
#define LINEENDS_CRLF_H
#define RAMP(x) \
    smoothstep(0.2, \
               0.8, (x))
#endif
