/*
 * wire.c: sending and receiving the farm's messages on ZeroMQ sockets
 * (the interface and its promises: wire.h; the framing and the limits:
 * docs/protocol.md).
 *
 * Receiving is where a hostile or broken peer meets our memory, so it
 * goes in stages, each bounding what the next may do:
 *   1. read every frame of the message (ZeroMQ delivers them together),
 *      keeping at most routing id + header + bulk and closing the rest;
 *   2. frame count and frame sizes against the limits;
 *   3. protobuf-c unpack through an allocator with a budget
 *      (unpack_factor x header bytes + 64 KiB), so a small header cannot
 *      expand into a large tree of empty submessages;
 *   4. proto_message_check() and the direction (who may send what).
 * A message failing any stage is counted and dropped.
 *
 * The liveness monitor decodes ZeroMQ's socket-monitor events (zmq.h,
 * zmq_socket_monitor: a 6-byte frame with the event number and value,
 * then a frame with the endpoint).
 */
#include "wire_pb.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zmq.h>

#include "util/xalloc.h"

#define MAX_ROUTING_ID 255 /* ZeroMQ routing ids are 1..255 bytes */
#define LINGER_MS 200
#define UNPACK_SLACK (64u << 10)

/* ---------------------------------------------------------------------- */
/* errors                                                                  */
/* ---------------------------------------------------------------------- */

/* err_set that also sets errno (callers tell EAGAIN from the rest). */
#if defined(__GNUC__)
__attribute__((format(printf, 4, 5)))
#endif
static void set_error(char *err, size_t errsz, int errnum, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    err_vset(err, errsz, fmt, ap);
    va_end(ap);
    errno = errnum;
}

static int socket_type(void *socket)
{
    int type = -1;
    size_t size = sizeof type;
    if (zmq_getsockopt(socket, ZMQ_TYPE, &type, &size) != 0)
        return -1;
    return type;
}

/* ---------------------------------------------------------------------- */
/* setup                                                                   */
/* ---------------------------------------------------------------------- */

int wire_socket_setup(void *socket, const proto_limits *limits, char *err, size_t errsz)
{
    proto_limits defaults = proto_limits_default();
    const proto_limits *l = limits ? limits : &defaults;
    size_t biggest = l->max_header_bytes > l->max_bulk_bytes ? l->max_header_bytes
                                                             : l->max_bulk_bytes;
    int64_t maxmsg = (int64_t)biggest;
    int linger = LINGER_MS, on = 1;
    int type = socket_type(socket);
    if (type < 0) {
        set_error(err, errsz, errno, "not a ZeroMQ socket: %s", zmq_strerror(errno));
        return -1;
    }
    if (zmq_setsockopt(socket, ZMQ_MAXMSGSIZE, &maxmsg, sizeof maxmsg) != 0 ||
        zmq_setsockopt(socket, ZMQ_LINGER, &linger, sizeof linger) != 0 ||
        (type == ZMQ_ROUTER &&
         zmq_setsockopt(socket, ZMQ_ROUTER_MANDATORY, &on, sizeof on) != 0)) {
        set_error(err, errsz, errno, "setting socket options: %s", zmq_strerror(errno));
        return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------------- */
/* sending                                                                 */
/* ---------------------------------------------------------------------- */

static void free_packed(void *data, void *hint)
{
    (void)hint;
    free(data);
}

/* Arguments and direction: a ROUTER is the master, a DEALER a worker. */
static int check_send_args(int type, const void *identity, size_t id_len,
                           const Aafarm__Envelope *msg, char *err, size_t errsz)
{
    if (!msg) {
        set_error(err, errsz, EINVAL, "wire_send: no message");
        return -1;
    }
    if (type != ZMQ_ROUTER && type != ZMQ_DEALER) {
        set_error(err, errsz, EINVAL, "wire_send: the socket is neither ROUTER nor DEALER");
        return -1;
    }
    if (type == ZMQ_ROUTER && (!identity || id_len == 0 || id_len > MAX_ROUTING_ID)) {
        set_error(err, errsz, EINVAL, "wire_send: a ROUTER needs the worker's routing id (1..255 bytes)");
        return -1;
    }
    if (type == ZMQ_DEALER && identity) {
        set_error(err, errsz, EINVAL, "wire_send: a DEALER sends no routing id");
        return -1;
    }
    bool master = type == ZMQ_ROUTER;
    proto_kind kind = (proto_kind)msg->body_case;
    if (master ? !proto_message_from_master(kind) : !proto_message_from_worker(kind)) {
        set_error(err, errsz, EPROTO, "wire_send: %s is not a message the %s sends",
                  proto_message_name(kind), master ? "master" : "worker");
        return -1;
    }
    return 0;
}

/* The packed header as a zero-copy ZeroMQ frame. */
static int pack_header(const Aafarm__Envelope *msg, const proto_limits *l, zmq_msg_t *frame,
                       char *err, size_t errsz)
{
    size_t size = aafarm__envelope__get_packed_size(msg);
    if (size > l->max_header_bytes) {
        set_error(err, errsz, EMSGSIZE, "wire_send: %s header is %zu bytes, the limit is %zu",
                  proto_message_name((proto_kind)msg->body_case), size, l->max_header_bytes);
        return -1;
    }
    uint8_t *buf = xmalloc(size ? size : 1);   /* our own message: never fails */
    aafarm__envelope__pack(msg, buf);
    if (zmq_msg_init_data(frame, buf, size, free_packed, NULL) != 0) {
        free(buf);
        set_error(err, errsz, errno, "wire_send: %s", zmq_strerror(errno));
        return -1;
    }
    return 0;
}

static int send_frames(void *socket, const void *identity, size_t id_len, zmq_msg_t *header,
                       const void *bulk, size_t bulk_len)
{
    if (identity && zmq_send(socket, identity, id_len, ZMQ_SNDMORE | ZMQ_DONTWAIT) < 0) {
        zmq_msg_close(header);
        return -1;
    }
    int more = bulk ? ZMQ_SNDMORE : 0;
    if (zmq_msg_send(header, socket, more | ZMQ_DONTWAIT) < 0) {
        zmq_msg_close(header);
        return -1;
    }
    if (bulk && zmq_send(socket, bulk, bulk_len, ZMQ_DONTWAIT) < 0)
        return -1;
    return 0;
}

int wire_send_envelope(void *socket, const proto_limits *limits, const void *identity,
                       size_t id_len, const Aafarm__Envelope *msg, const void *bulk,
                       size_t bulk_len, char *err, size_t errsz)
{
    proto_limits defaults = proto_limits_default();
    const proto_limits *l = limits ? limits : &defaults;
    if (check_send_args(socket_type(socket), identity, id_len, msg, err, errsz) != 0)
        return -1;
    char why[ERR_LEN];
    if (!proto_message_check(msg, bulk != NULL, bulk_len, l, why, sizeof why)) {
        set_error(err, errsz, EPROTO, "wire_send: %s", why);
        return -1;
    }
    zmq_msg_t header;
    if (pack_header(msg, l, &header, err, errsz) != 0)
        return -1;
    if (send_frames(socket, identity, id_len, &header, bulk, bulk_len) != 0) {
        set_error(err, errsz, errno, "wire_send: %s: %s",
                  proto_message_name((proto_kind)msg->body_case), zmq_strerror(errno));
        return -1;
    }
    return 0;
}

int wire_send_limited(void *socket, const proto_limits *limits, const void *identity,
                      size_t id_len, const proto_msg *msg, const void *bulk, size_t bulk_len,
                      char *err, size_t errsz)
{
    if (!msg)
        return wire_send_envelope(socket, limits, identity, id_len, NULL, bulk, bulk_len, err,
                                  errsz);
    envelope_out out;
    envelope_out_init(&out, msg);
    int rc = wire_send_envelope(socket, limits, identity, id_len, &out.env, bulk, bulk_len, err,
                                errsz);
    int e = errno;
    envelope_out_clear(&out);
    errno = e;
    return rc;
}

int wire_send(void *socket, const void *identity, size_t id_len, const proto_msg *msg,
              const void *bulk, size_t bulk_len, char *err, size_t errsz)
{
    return wire_send_limited(socket, NULL, identity, id_len, msg, bulk, bulk_len, err, errsz);
}

/* ---------------------------------------------------------------------- */
/* the received message                                                    */
/* ---------------------------------------------------------------------- */

/* protobuf-c's memory for one header, with a ceiling. */
typedef struct unpack_budget {
    size_t left;
    bool exceeded;
} unpack_budget;

struct wire_msg {
    Aafarm__Envelope *env;
    proto_msg body;     /* the plain view of env */
    void *body_block;   /* its arrays (proto_msg_view) */
    zmq_msg_t bulk;
    bool has_bulk;
    uint8_t identity[MAX_ROUTING_ID];
    size_t identity_len;
    unpack_budget budget;
    ProtobufCAllocator allocator;
};

/* A peer chose the sizes: past the budget, or out of memory, protobuf-c
 * gets NULL and the message is refused (never an abort). */
static void *budget_alloc(void *data, size_t size)
{
    unpack_budget *b = data;
    if (size > b->left) {
        b->exceeded = true;
        return NULL;
    }
    b->left -= size;
    return try_malloc(size ? size : 1);
}

static void budget_free(void *data, void *p)
{
    (void)data;
    free(p);
}

void wire_msg_destroy(wire_msg **self_p)
{
    if (!self_p || !*self_p)
        return;
    wire_msg *self = *self_p;
    if (self->env)
        protobuf_c_message_free_unpacked(&self->env->base, &self->allocator);
    if (self->has_bulk)
        zmq_msg_close(&self->bulk);
    free(self->body_block);
    free(self);
    *self_p = NULL;
}

const Aafarm__Envelope *wire_msg_envelope(const wire_msg *self)
{
    return self ? self->env : NULL;
}

const proto_msg *wire_msg_body(const wire_msg *self)
{
    return self && self->env ? &self->body : NULL;
}

proto_kind wire_msg_kind(const wire_msg *self)
{
    return self && self->env ? (proto_kind)self->env->body_case : PROTO_NONE;
}

const uint8_t *wire_msg_bulk(const wire_msg *self, size_t *len)
{
    bool has = self && self->has_bulk;
    if (len)
        *len = has ? zmq_msg_size((zmq_msg_t *)&self->bulk) : 0;
    return has ? zmq_msg_data((zmq_msg_t *)&self->bulk) : NULL;
}

const uint8_t *wire_msg_identity(const wire_msg *self, size_t *len)
{
    bool has = self && self->identity_len > 0;
    if (len)
        *len = has ? self->identity_len : 0;
    return has ? self->identity : NULL;
}

/* ---------------------------------------------------------------------- */
/* receiving                                                               */
/* ---------------------------------------------------------------------- */

enum { MAX_KEPT = 3 }; /* routing id + header + bulk */

/* All frames of one message as read off the socket. */
typedef struct frames {
    zmq_msg_t part[MAX_KEPT];
    size_t kept;   /* frames held in part[] */
    size_t count;  /* frames the message had */
} frames;

static void frames_close(frames *f)
{
    for (size_t i = 0; i < f->kept; i++)
        zmq_msg_close(&f->part[i]);
    f->kept = 0;
}

/* Reads every frame of the next message; -1 (errno from ZeroMQ) when the
 * first frame could not be read. */
static int frames_read(void *socket, int flags, frames *f)
{
    f->kept = f->count = 0;
    for (;;) {
        zmq_msg_t part;
        zmq_msg_init(&part);
        if (zmq_msg_recv(&part, socket, f->count == 0 ? flags : 0) < 0) {
            int e = errno;
            zmq_msg_close(&part);
            if (f->count == 0) {
                errno = e;
                return -1;
            }
            return 0; /* cannot happen: the parts of a message arrive together */
        }
        bool more = zmq_msg_more(&part);
        f->count++;
        if (f->kept < MAX_KEPT) {
            zmq_msg_init(&f->part[f->kept]);
            zmq_msg_move(&f->part[f->kept++], &part);
        }
        zmq_msg_close(&part);
        if (!more)
            return 0;
    }
}

/* How one receive went, for the counters and the message. */
typedef enum verdict { V_OK, V_BAD_FRAMES, V_OVERSIZED, V_UNDECODABLE, V_INVALID } verdict;

typedef struct receiver {
    const proto_limits *limits;
    bool router;
    frames f;
    wire_msg *msg;
    char why[ERR_LEN];
} receiver;

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static verdict reject(receiver *r, verdict v, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->why, sizeof r->why, fmt, ap);
    va_end(ap);
    return v;
}

/* Stage 2: frame count and sizes; moves routing id and bulk into msg. */
static verdict take_frames(receiver *r, zmq_msg_t **header)
{
    size_t first = r->router ? 1 : 0; /* index of the header frame */
    size_t n = r->f.count - first;
    if (r->f.count <= first || n > 2)
        return reject(r, V_BAD_FRAMES, "message of %zu frames; expected %s", r->f.count,
                      r->router ? "3 at most (routing id, header, bulk)"
                                : "1 or 2 (header, bulk)");
    if (r->router) {
        size_t idlen = zmq_msg_size(&r->f.part[0]);
        if (idlen == 0 || idlen > MAX_ROUTING_ID)
            return reject(r, V_BAD_FRAMES, "routing id of %zu bytes", idlen);
    }
    *header = &r->f.part[first];
    size_t hlen = zmq_msg_size(*header);
    if (hlen == 0)
        return reject(r, V_BAD_FRAMES, "empty header frame");
    if (hlen > r->limits->max_header_bytes)
        return reject(r, V_OVERSIZED, "header frame of %zu bytes, the limit is %zu", hlen,
                      r->limits->max_header_bytes);
    if (n == 2 && zmq_msg_size(&r->f.part[first + 1]) > r->limits->max_bulk_bytes)
        return reject(r, V_OVERSIZED, "bulk frame of %zu bytes, the limit is %zu",
                      zmq_msg_size(&r->f.part[first + 1]), r->limits->max_bulk_bytes);
    return V_OK;
}

/* Stage 3: protobuf-c unpack within the memory budget. */
static verdict unpack(receiver *r, zmq_msg_t *header)
{
    wire_msg *m = r->msg;
    size_t hlen = zmq_msg_size(header);
    m->budget.left = r->limits->unpack_factor * hlen + UNPACK_SLACK;
    m->allocator.alloc = budget_alloc;
    m->allocator.free = budget_free;
    m->allocator.allocator_data = &m->budget;
    m->env = aafarm__envelope__unpack(&m->allocator, hlen, zmq_msg_data(header));
    if (m->env)
        return V_OK;
    if (m->budget.exceeded)
        return reject(r, V_UNDECODABLE, "header of %zu bytes would need more than %zu bytes "
                      "of memory unpacked", hlen, r->limits->unpack_factor * hlen + UNPACK_SLACK);
    return reject(r, V_UNDECODABLE, "header of %zu bytes is not an aafarm Envelope "
                  "(protobuf decoding failed)", hlen);
}

/* Stage 4: fields and direction. */
static verdict judge(receiver *r, bool has_bulk, size_t bulk_len)
{
    const Aafarm__Envelope *env = r->msg->env;
    if (!proto_message_check(env, has_bulk, bulk_len, r->limits, r->why, sizeof r->why))
        return V_INVALID;
    proto_kind kind = (proto_kind)env->body_case;
    bool ok = r->router ? proto_message_from_worker(kind) : proto_message_from_master(kind);
    if (!ok)
        return reject(r, V_INVALID, "%s is a %s's message; it cannot arrive at the %s",
                      proto_message_name(kind), r->router ? "master" : "worker",
                      r->router ? "master" : "worker");
    if (!proto_msg_view(env, &r->msg->body, &r->msg->body_block))
        return reject(r, V_UNDECODABLE, "out of memory for the %s's arrays",
                      proto_message_name(kind));
    return V_OK;
}

static verdict receive_stages(receiver *r)
{
    zmq_msg_t *header = NULL;
    verdict v = take_frames(r, &header);
    if (v != V_OK)
        return v;
    wire_msg *m = r->msg;
    if (r->router) {
        m->identity_len = zmq_msg_size(&r->f.part[0]);
        memcpy(m->identity, zmq_msg_data(&r->f.part[0]), m->identity_len);
    }
    v = unpack(r, header);
    if (v != V_OK)
        return v;
    size_t bulk_at = r->router ? 2 : 1;
    bool has_bulk = r->f.kept > bulk_at;
    v = judge(r, has_bulk, has_bulk ? zmq_msg_size(&r->f.part[bulk_at]) : 0);
    if (v == V_OK && has_bulk) {
        zmq_msg_init(&m->bulk);
        zmq_msg_move(&m->bulk, &r->f.part[bulk_at]);
        m->has_bulk = true;
    }
    return v;
}

static void count(wire_stats *stats, verdict v)
{
    if (!stats)
        return;
    switch (v) {
    case V_OK: stats->received++; return;
    case V_BAD_FRAMES: stats->bad_frames++; break;
    case V_OVERSIZED: stats->oversized++; break;
    case V_UNDECODABLE: stats->undecodable++; break;
    case V_INVALID: stats->invalid++; break;
    }
    stats->dropped++;
}

/* "from peer 00 6b 8b 45 67: <why>" (ROUTER) or "from the master: <why>". */
static void explain(receiver *r, wire_stats *stats, char *err, size_t errsz)
{
    char peer[2 * 16 + 16] = "the master";
    if (r->router && r->f.kept > 0) {
        size_t n = zmq_msg_size(&r->f.part[0]);
        const uint8_t *id = zmq_msg_data(&r->f.part[0]);
        int at = snprintf(peer, sizeof peer, "peer ");
        for (size_t i = 0; i < n && i < 16; i++)
            at += snprintf(peer + at, sizeof peer - (size_t)at, "%02x", id[i]);
        if (n > 16)
            snprintf(peer + at, sizeof peer - (size_t)at, "...");
    }
    set_error(err, errsz, EPROTO, "dropped a message from %s: %s", peer, r->why);
    if (stats)
        err_set(stats->last_error, sizeof stats->last_error, "dropped a message from %s: %s",
                peer, r->why);
}

wire_msg *wire_recv(void *socket, const proto_limits *limits, wire_stats *stats, int flags,
                    char *err, size_t errsz)
{
    proto_limits defaults = proto_limits_default();
    receiver r = {.limits = limits ? limits : &defaults};
    int type = socket_type(socket);
    if (type != ZMQ_ROUTER && type != ZMQ_DEALER) {
        set_error(err, errsz, type < 0 ? errno : ENOTSUP, "wire_recv: the socket is neither ROUTER nor DEALER");
        return NULL;
    }
    r.router = type == ZMQ_ROUTER;
    if (frames_read(socket, flags, &r.f) != 0) {
        set_error(err, errsz, errno, "wire_recv: %s", zmq_strerror(errno));
        return NULL;
    }
    r.msg = try_calloc(1, sizeof *r.msg);
    verdict v = r.msg ? receive_stages(&r) : reject(&r, V_INVALID, "out of memory");
    count(stats, v);
    if (v != V_OK) {
        explain(&r, stats, err, errsz);
        wire_msg_destroy(&r.msg);
    }
    frames_close(&r.f);
    if (v != V_OK)
        errno = EPROTO;
    return r.msg;
}

/* ---------------------------------------------------------------------- */
/* the socket monitor                                                      */
/* ---------------------------------------------------------------------- */

struct wire_monitor {
    void *watched;  /* the monitored socket */
    void *pair;     /* where its events arrive */
};

wire_monitor *wire_monitor_new(void *ctx, void *socket, char *err, size_t errsz)
{
    static _Atomic unsigned long serial;
    char endpoint[64];
    snprintf(endpoint, sizeof endpoint, "inproc://wire-monitor-%lu", ++serial);
    wire_monitor *self = xcalloc(1, sizeof *self);
    int events = ZMQ_EVENT_CONNECTED | ZMQ_EVENT_ACCEPTED | ZMQ_EVENT_DISCONNECTED |
                 ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL | ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL |
                 ZMQ_EVENT_HANDSHAKE_FAILED_AUTH;
    self->watched = socket;
    if (zmq_socket_monitor(socket, endpoint, events) != 0 ||
        !(self->pair = zmq_socket(ctx, ZMQ_PAIR)) || zmq_connect(self->pair, endpoint) != 0) {
        set_error(err, errsz, errno, "wire_monitor_new: %s", zmq_strerror(errno));
        wire_monitor_destroy(&self);
        return NULL;
    }
    return self;
}

/* Reads one event (both frames); its number, or -1 when none is pending.
 * The endpoint it names goes to where[0..wheresz). */
static int read_event(void *pair, char *where_out, size_t wheresz)
{
    zmq_msg_t head, where;
    zmq_msg_init(&head);
    if (zmq_msg_recv(&head, pair, ZMQ_DONTWAIT) < 0) {
        int e = errno;
        zmq_msg_close(&head);
        errno = e;
        return -1;
    }
    int event = 0;
    if (zmq_msg_size(&head) >= 2) {
        const uint8_t *d = zmq_msg_data(&head);
        uint16_t number;
        memcpy(&number, d, sizeof number); /* host byte order, as zmq.h says */
        event = number;
    }
    bool more = zmq_msg_more(&head);
    zmq_msg_close(&head);
    where_out[0] = '\0';
    while (more) {
        zmq_msg_init(&where);
        if (zmq_msg_recv(&where, pair, 0) < 0) {
            zmq_msg_close(&where);
            break;
        }
        size_t len = zmq_msg_size(&where);
        if (len >= wheresz) len = wheresz - 1;
        memcpy(where_out, zmq_msg_data(&where), len);
        where_out[len] = '\0';
        more = zmq_msg_more(&where);
        zmq_msg_close(&where);
    }
    return event;
}

int wire_monitor_poll(wire_monitor *self, wire_stats *stats, char *err, size_t errsz)
{
    if (!self || !self->pair) {
        set_error(err, errsz, EINVAL, "wire_monitor_poll: no monitor");
        return -1;
    }
    int n = 0;
    char where[128];
    for (int event; (event = read_event(self->pair, where, sizeof where)) >= 0; n++) {
        if (!stats)
            continue;
        if (event == ZMQ_EVENT_CONNECTED || event == ZMQ_EVENT_ACCEPTED)
            stats->connects++;
        else if (event == ZMQ_EVENT_DISCONNECTED)
            stats->disconnects++;
        else if (event == ZMQ_EVENT_HANDSHAKE_FAILED_NO_DETAIL ||
                 event == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL ||
                 event == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) {
            stats->handshake_failures++;
            if (event == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH) stats->auth_failures++;
            snprintf(stats->last_handshake, sizeof stats->last_handshake, "%s on %s",
                     event == ZMQ_EVENT_HANDSHAKE_FAILED_AUTH       ? "refused by authentication"
                     : event == ZMQ_EVENT_HANDSHAKE_FAILED_PROTOCOL ? "protocol or security mismatch"
                                                                    : "failed",
                     where[0] ? where : "?");
        }
    }
    if (errno != EAGAIN) {
        set_error(err, errsz, errno, "wire_monitor_poll: %s", zmq_strerror(errno));
        return -1;
    }
    return n;
}

void *wire_monitor_socket(wire_monitor *self)
{
    return self ? self->pair : NULL;
}

void wire_monitor_destroy(wire_monitor **self_p)
{
    if (!self_p || !*self_p)
        return;
    wire_monitor *self = *self_p;
    zmq_socket_monitor(self->watched, NULL, 0);
    if (self->pair) {
        int linger = 0;
        zmq_setsockopt(self->pair, ZMQ_LINGER, &linger, sizeof linger);
        zmq_close(self->pair);
    }
    free(self);
    *self_p = NULL;
}
