/* The fast flooder of tools/link_flood.py (FLOOD_IMPL=c): sends the datagrams of a file, round
 * robin, to a multicast group with sendmmsg (ttl 0: the loopback of the network namespace) until
 * a wall-clock deadline, and prints how many datagrams the kernel took (sendmmsg's count; a batch
 * refused with ENOBUFS under saturation is not counted).
 * File format: repeated [uint32 big-endian length][bytes].
 * Usage: link_flood_sender FILE GROUP PORT STOP_AT_UNIX_S */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

enum { kMax = 256, kBatch = 64 };

static double now_s(void) {
  struct timeval tv;
  gettimeofday(&tv, NULL);
  return (double)tv.tv_sec + 1e-6 * (double)tv.tv_usec;
}

int main(int argc, char** argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: link_flood_sender FILE GROUP PORT STOP_AT_UNIX_S\n");
    return 2;
  }
  FILE* f = fopen(argv[1], "rb");
  if (!f) {
    perror(argv[1]);
    return 1;
  }
  static unsigned char data[kMax][65536];
  static size_t size[kMax];
  int n = 0;
  unsigned char len[4];
  while (n < kMax && fread(len, 1, 4, f) == 4) {
    size[n] = ((size_t)len[0] << 24) | ((size_t)len[1] << 16) | ((size_t)len[2] << 8) | len[3];
    if (size[n] > sizeof data[0] || fread(data[n], 1, size[n], f) != size[n]) break;
    ++n;
  }
  fclose(f);
  if (n == 0) {
    fprintf(stderr, "%s: no datagrams\n", argv[1]);
    return 1;
  }
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  const unsigned char ttl = 0;
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
  struct sockaddr_in to;
  memset(&to, 0, sizeof to);
  to.sin_family = AF_INET;
  to.sin_port = htons((uint16_t)atoi(argv[3]));
  inet_pton(AF_INET, argv[2], &to.sin_addr);
  const double stop_at = atof(argv[4]);
  struct mmsghdr msgs[kBatch];
  struct iovec iov[kBatch];
  long long sent = 0;
  while (now_s() < stop_at) {
    for (int k = 0; k < 32; ++k) {
      for (int i = 0; i < kBatch; ++i) {
        const int j = (int)((unsigned)(k * kBatch + i) % (unsigned)n);
        iov[i].iov_base = data[j];
        iov[i].iov_len = size[j];
        memset(&msgs[i], 0, sizeof msgs[i]);
        msgs[i].msg_hdr.msg_name = &to;
        msgs[i].msg_hdr.msg_namelen = sizeof to;
        msgs[i].msg_hdr.msg_iov = &iov[i];
        msgs[i].msg_hdr.msg_iovlen = 1;
      }
      const int r = sendmmsg(fd, msgs, kBatch, 0);
      if (r > 0) sent += r;
    }
  }
  printf("%lld\n", sent);
  return 0;
}
