// crane_packet_delay: delays every packet of a netfilter queue by a fixed time, in order (the
// "delay" fault of deploy/site_hosts.sh, on a kernel without tc netem: docs/site.md, "Faults
// between hosts"). The packets reach it through an iptables NFQUEUE rule (--queue-bypass, so that
// they pass undelayed if this process is gone); each is held for --delay-ms from its arrival and then
// accepted, oldest first, so the stream keeps its order (netem's delay without jitter). Only the
// packet's metadata is copied to this process; nothing is altered or dropped.
//
// Exit: 0 on SIGINT/SIGTERM, after every held packet was accepted; 1 when the queue cannot be bound
// (not root, no nfnetlink_queue in the kernel) or the netlink socket fails; 2 on a bad option.
#include <arpa/inet.h>
#include <libnetfilter_queue/libnetfilter_queue.h>
#include <linux/netfilter.h>
#include <poll.h>
#include <sys/socket.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>

namespace {
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

struct Held {
  std::uint32_t id;
  Clock::time_point release;
};

struct Queue {
  std::deque<Held> held;
  Clock::duration delay{};
  std::uint64_t packets{0};
  std::size_t most_held{0};
};

int on_packet(nfq_q_handle*, nfgenmsg*, nfq_data* data, void* context) {
  auto& q = *static_cast<Queue*>(context);
  const nfqnl_msg_packet_hdr* header = nfq_get_msg_packet_hdr(data);
  if (header == nullptr) return 0;
  q.held.push_back({ntohl(header->packet_id), Clock::now() + q.delay});
  ++q.packets;
  q.most_held = std::max(q.most_held, q.held.size());
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_packet_delay: hold every packet of a netfilter queue for a fixed time, in order"};
  unsigned queue_number = 0;
  double delay_ms = 0.0;
  app.add_option("--queue", queue_number, "the NFQUEUE number the iptables rule sends to")->check(CLI::Range(0, 65535));
  app.add_option("--delay-ms", delay_ms, "[ms] how long each packet is held")->required()->check(CLI::Range(0.0, 10000.0));
  CLI11_PARSE(app, argc, argv);

  Queue q;
  q.delay = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(delay_ms));
  nfq_handle* handle = nfq_open();
  if (handle == nullptr) {
    std::fprintf(stderr, "crane_packet_delay: nfq_open: %s (root and nfnetlink_queue needed)\n", std::strerror(errno));
    return 1;
  }
  nfq_q_handle* queue = nfq_create_queue(handle, static_cast<std::uint16_t>(queue_number), &on_packet, &q);
  if (queue == nullptr) {
    std::fprintf(stderr, "crane_packet_delay: queue %u cannot be bound: %s\n", queue_number, std::strerror(errno));
    nfq_close(handle);
    return 1;
  }
  // Metadata only (the verdict needs the id alone); room for the packets of a 10 s delay at 2 kpkt/s.
  if (nfq_set_mode(queue, NFQNL_COPY_META, 0) < 0 || nfq_set_queue_maxlen(queue, 20000) < 0) {
    std::fprintf(stderr, "crane_packet_delay: queue %u: copy mode or length refused: %s\n", queue_number,
                 std::strerror(errno));
    nfq_destroy_queue(queue);
    nfq_close(handle);
    return 1;
  }
  const int fd = nfq_fd(handle);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::printf("crane_packet_delay: queue %u, every packet held %.1f ms\n", queue_number, delay_ms);
  std::fflush(stdout);

  alignas(8) char buffer[65536];
  int status = 0;
  while (g_stop == 0) {
    const auto now = Clock::now();
    while (!q.held.empty() && q.held.front().release <= now) {
      nfq_set_verdict(queue, q.held.front().id, NF_ACCEPT, 0, nullptr);
      q.held.pop_front();
    }
    int timeout_ms = 100;
    if (!q.held.empty()) {
      const auto wait = std::chrono::ceil<std::chrono::milliseconds>(q.held.front().release - now).count();
      timeout_ms = static_cast<int>(std::clamp<long long>(wait, 0, 100));
    }
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, timeout_ms);
    if (ready < 0) {
      if (errno == EINTR) continue;
      std::fprintf(stderr, "crane_packet_delay: poll: %s\n", std::strerror(errno));
      status = 1;
      break;
    }
    if (ready == 0) continue;
    const ssize_t n = ::recv(fd, buffer, sizeof(buffer), MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      if (errno == ENOBUFS) {  // the kernel dropped queue messages: those packets were dropped by it
        std::fprintf(stderr, "crane_packet_delay: the netlink socket overran (ENOBUFS): packets lost\n");
        continue;
      }
      std::fprintf(stderr, "crane_packet_delay: recv: %s\n", std::strerror(errno));
      status = 1;
      break;
    }
    nfq_handle_packet(handle, buffer, static_cast<int>(n));
  }
  // Nothing held back at the end: every packet still held passes now.
  for (const auto& h : q.held) nfq_set_verdict(queue, h.id, NF_ACCEPT, 0, nullptr);
  std::printf("crane_packet_delay: queue %u done: %llu packets delayed, at most %zu held at once\n", queue_number,
              static_cast<unsigned long long>(q.packets), q.most_held);
  nfq_destroy_queue(queue);
  nfq_close(handle);
  return status;
}
