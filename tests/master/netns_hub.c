/*
 * netns_hub.c: a userspace Ethernet hub with delay and loss, for the
 * multi-host test (test_farm_netns.c) on kernels without the netem qdisc.
 *
 *   netns_hub DELAY_MS LOSS_PERCENT IFACE...
 *
 * Every frame that arrives on one interface (raw AF_PACKET sockets, one
 * per interface, with virtio-net headers so that the large GSO frames
 * veth passes along are forwarded whole) is sent out of every other
 * interface DELAY_MS later, unless it is dropped, with probability
 * LOSS_PERCENT / 100 per frame. A hub, not a switch: each host sees the
 * others' frames and its kernel ignores those not addressed to it. It
 * stands in for "tc qdisc add ... netem delay D loss L" on the link of
 * every host (one-way delay D between any two hosts). Runs until SIGTERM;
 * an interface that goes down (a partition) just loses what is sent to it.
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <linux/if_packet.h>
#include <linux/if_ether.h>
#include <net/if.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#ifndef PACKET_IGNORE_OUTGOING
#define PACKET_IGNORE_OUTGOING 23
#endif

enum { MAX_PORTS = 8, MAX_QUEUED = 8192, FRAME_MAX = 65536 + 64 };

typedef struct frame {
    int64_t due_us;
    int from;
    size_t len;
    uint8_t *data;
} frame;

static volatile sig_atomic_t stop;
static void on_signal(int sig) { (void)sig; stop = 1; }

static int64_t now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static int open_port(const char *name)
{
    int s = socket(AF_PACKET, SOCK_RAW, htons(ETH_P_ALL));
    int one = 1;
    unsigned idx = if_nametoindex(name);
    if (s < 0 || idx == 0) return -1;
    if (setsockopt(s, SOL_PACKET, PACKET_VNET_HDR, &one, sizeof one) != 0) return -1;
    setsockopt(s, SOL_PACKET, PACKET_IGNORE_OUTGOING, &one, sizeof one);
    struct sockaddr_ll a;
    memset(&a, 0, sizeof a);
    a.sll_family = AF_PACKET;
    a.sll_protocol = htons(ETH_P_ALL);
    a.sll_ifindex = (int)idx;
    if (bind(s, (struct sockaddr *)&a, sizeof a) != 0) return -1;
    return s;
}

int main(int argc, char **argv)
{
    if (argc < 4 || argc - 3 > MAX_PORTS) {
        fprintf(stderr, "usage: netns_hub DELAY_MS LOSS_PERCENT IFACE... (2..%d)\n", MAX_PORTS);
        return 2;
    }
    int64_t delay_us = atol(argv[1]) * 1000;
    double loss = atof(argv[2]) / 100.0;
    int nports = argc - 3, fd[MAX_PORTS];
    for (int i = 0; i < nports; i++) {
        fd[i] = open_port(argv[3 + i]);
        if (fd[i] < 0) {
            fprintf(stderr, "netns_hub: %s: %s\n", argv[3 + i], strerror(errno));
            return 1;
        }
    }
    signal(SIGTERM, on_signal);
    signal(SIGINT, on_signal);
    srand48((long)getpid() ^ (long)now_us());
    static frame q[MAX_QUEUED];   /* a ring, in arrival (= due) order */
    size_t head = 0, count = 0;
    uint64_t forwarded = 0, dropped = 0, overflow = 0;
    printf("netns_hub: %d ports, delay %ld ms, loss %.1f %%\n", nports, (long)(delay_us / 1000),
           loss * 100);
    fflush(stdout);
    while (!stop) {
        struct pollfd p[MAX_PORTS];
        for (int i = 0; i < nports; i++) p[i] = (struct pollfd){fd[i], POLLIN, 0};
        int wait_ms = 100;
        if (count) {
            int64_t d = q[head].due_us - now_us();
            wait_ms = d <= 0 ? 0 : (int)((d + 999) / 1000);
        }
        poll(p, (nfds_t)nports, wait_ms);
        for (int i = 0; i < nports; i++) {
            if (!(p[i].revents & POLLIN)) continue;
            for (;;) {
                uint8_t buf[FRAME_MAX];
                ssize_t n = recv(fd[i], buf, sizeof buf, MSG_DONTWAIT);
                if (n <= 0) break;
                if (drand48() < loss) {
                    dropped++;
                    continue;
                }
                if (count == MAX_QUEUED) {
                    overflow++;
                    continue;
                }
                frame *f = &q[(head + count++) % MAX_QUEUED];
                f->due_us = now_us() + delay_us;
                f->from = i;
                f->len = (size_t)n;
                f->data = malloc((size_t)n);
                if (!f->data) abort();
                memcpy(f->data, buf, (size_t)n);
            }
        }
        for (int64_t t = now_us(); count && q[head].due_us <= t;) {
            frame *f = &q[head];
            for (int j = 0; j < nports; j++)
                if (j != f->from) send(fd[j], f->data, f->len, MSG_DONTWAIT);
            free(f->data);
            head = (head + 1) % MAX_QUEUED;
            count--;
            forwarded++;
        }
    }
    /* frames still queued at SIGTERM: freed, so that a sanitizer build
     * exits at once instead of reporting (and symbolising) each as a leak */
    for (; count; count--, head = (head + 1) % MAX_QUEUED)
        free(q[head].data);
    printf("netns_hub: forwarded %llu frames, dropped %llu (loss), %llu (queue full)\n",
           (unsigned long long)forwarded, (unsigned long long)dropped,
           (unsigned long long)overflow);
    return 0;
}
