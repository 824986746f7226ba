// Frame round trip over the EtherCAT link: RawSocketLink on one end of a veth pair (namespace A)
// to an echo process on the other end (namespace B, its own RawSocketLink) and back, against the
// same round trip of a UDP datagram over loopback to an echo process (namespace A's lo). The two
// alternate in blocks so both see the same machine. Needs root (namespaces, veth, raw sockets).
// Prints figures; asserts nothing.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "tests/ethercat_link/frames.hpp"
#include "tests/support/netns.hpp"

namespace {

using drivegate::ethercat::FrameBuffer;
using drivegate::ethercat::FrameView;
using drivegate::ethercat::RawSocketLink;
using drivegate::ethercat::RawSocketOptions;
using drivegate::test::ChildProcess;
using drivegate::test::NetNamespace;
using drivegate::test::NetnsScope;
using drivegate::test::VethPair;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

struct Options {
  std::size_t frames = 20000;  // measured round trips per path
  std::size_t block = 1000;    // round trips per path before switching to the other
  std::size_t size = 60;       // frame bytes (UDP: the same number of payload bytes)
  bool busy = false;           // spin on receive instead of waiting in poll()
};

void usage() {
  std::fprintf(stderr, "usage: bench_ethercat_link_rtt [--frames N] [--block N] [--size BYTES] [--busy]\n");
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::size_t {
      if (i + 1 >= argc) usage();
      return static_cast<std::size_t>(std::strtoull(argv[++i], nullptr, 10));
    };
    if (a == "--frames") o.frames = value();
    else if (a == "--block") o.block = value();
    else if (a == "--size") o.size = value();
    else if (a == "--busy") o.busy = true;
    else usage();
  }
  // Bytes 16..23 carry the sequence number: no frame shorter than that.
  o.size = std::clamp<std::size_t>(o.size, 24, drivegate::ethercat::kMaxFrameSize);
  o.block = std::max<std::size_t>(o.block, 1);
  return o;
}

bool wait_in(int fd, bool busy) {
  if (busy) return true;
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, 1000) > 0;
}

// One raw round trip: send, then receive until the frame with `seq` is back; its time in ns, or -1.
double raw_round_trip(RawSocketLink& link, std::vector<std::uint8_t>& frame, std::uint64_t seq, FrameBuffer& in, bool busy) {
  std::memcpy(frame.data() + 16, &seq, sizeof seq);
  const auto t0 = Clock::now();
  if (link.send(FrameView(frame)).sent != 1) return -1;
  for (;;) {
    if (!wait_in(link.wait_fd(), busy)) return -1;
    if (link.receive({&in, 1}) != 1) continue;
    std::uint64_t back = 0;
    std::memcpy(&back, in.bytes.data() + 16, sizeof back);
    if (back == seq) return static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count());
  }
}

double udp_round_trip(int fd, std::vector<std::uint8_t>& payload, std::uint64_t seq, std::vector<std::uint8_t>& in, bool busy) {
  std::memcpy(payload.data(), &seq, sizeof seq);
  const auto t0 = Clock::now();
  if (::send(fd, payload.data(), payload.size(), MSG_DONTWAIT) != static_cast<ssize_t>(payload.size())) return -1;
  for (;;) {
    if (!wait_in(fd, busy)) return -1;
    const ssize_t n = ::recv(fd, in.data(), in.size(), MSG_DONTWAIT);
    if (n < static_cast<ssize_t>(sizeof seq)) continue;
    std::uint64_t back = 0;
    std::memcpy(&back, in.data(), sizeof back);
    if (back == seq) return static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count());
  }
}

// The echo ends, each in a child process (it writes one line once it is ready).
int raw_echo(const std::string& iface, int out) {
  RawSocketOptions o;
  o.interface = iface;
  RawSocketLink link(o);
  try {
    link.open();
  } catch (const std::exception& e) {
    drivegate::test::write_line(out, e.what());
    return 1;
  }
  drivegate::test::write_line(out, "ready");
  std::vector<FrameBuffer> in(drivegate::ethercat::kLinkBatch);
  std::vector<FrameView> back(in.size());
  for (;;) {
    pollfd p{link.wait_fd(), POLLIN, 0};
    ::poll(&p, 1, -1);
    const std::size_t n = link.receive(in);
    for (std::size_t i = 0; i < n; ++i) back[i] = in[i].view();
    link.send(std::span<const FrameView>(back.data(), n));
  }
}

int udp_echo(int out) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    drivegate::test::write_line(out, std::string("udp echo: ") + std::strerror(errno));
    return 1;
  }
  drivegate::test::write_line(out, std::to_string(ntohs(a.sin_port)));
  std::vector<std::uint8_t> buf(65536);
  for (;;) {
    sockaddr_in from{};
    socklen_t from_len = sizeof from;
    const ssize_t n = ::recvfrom(fd, buf.data(), buf.size(), 0, reinterpret_cast<sockaddr*>(&from), &from_len);
    if (n > 0) ::sendto(fd, buf.data(), static_cast<std::size_t>(n), 0, reinterpret_cast<sockaddr*>(&from), from_len);
  }
}

struct Summary {
  double min = 0, p50 = 0, p99 = 0, max = 0;
  std::size_t lost = 0;
};

Summary summarise(std::vector<double> v, std::size_t lost) {
  Summary s;
  s.lost = lost;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) { return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))]; };
  s.min = v.front() / 1000.0;
  s.p50 = at(0.5) / 1000.0;
  s.p99 = at(0.99) / 1000.0;
  s.max = v.back() / 1000.0;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  if (const std::string& why = drivegate::test::netns_unavailable(); !why.empty()) {
    std::fprintf(stderr, "bench_ethercat_link_rtt: cannot run: %s\n", why.c_str());
    return 1;
  }
  NetNamespace ns_a;
  NetNamespace ns_b;
  VethPair veth(&ns_a, &ns_b);

  const std::string b_name = veth.b();
  ChildProcess raw_peer(&ns_b, [&b_name](int out) { return raw_echo(b_name, out); });
  ChildProcess udp_peer(&ns_a, [](int out) { return udp_echo(out); });
  const auto raw_ready = raw_peer.read_line(5s);
  const auto udp_port = udp_peer.read_line(5s);
  if (!raw_ready || *raw_ready != "ready" || !udp_port || std::atoi(udp_port->c_str()) <= 0) {
    std::fprintf(stderr, "bench_ethercat_link_rtt: echo processes did not start: %s / %s\n",
                 raw_ready.value_or("(nothing)").c_str(), udp_port.value_or("(nothing)").c_str());
    return 1;
  }

  RawSocketOptions ro;
  ro.interface = veth.a();
  RawSocketLink link(ro);
  int udp = -1;
  {
    const NetnsScope in(ns_a);
    link.open();
    udp = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons(static_cast<std::uint16_t>(std::atoi(udp_port->c_str())));
    if (udp < 0 || ::connect(udp, reinterpret_cast<sockaddr*>(&to), sizeof to) != 0) {
      std::fprintf(stderr, "bench_ethercat_link_rtt: udp socket: %s\n", std::strerror(errno));
      return 1;
    }
  }

  // An EtherCAT-typed frame; bytes 16..23 carry the sequence number (the link does not look).
  auto frame = drivegate::ethercat::test::make_frame(0, o.size);
  std::vector<std::uint8_t> payload(o.size, 0);
  std::vector<std::uint8_t> udp_in(65536);
  auto in = std::make_unique<FrameBuffer>();
  std::vector<double> raw_ns;
  std::vector<double> udp_ns;
  raw_ns.reserve(o.frames);
  udp_ns.reserve(o.frames);
  std::size_t raw_lost = 0;
  std::size_t udp_lost = 0;
  std::uint64_t seq = 1;
  // Warm-up: caches, the echo processes' first wake-ups.
  for (int i = 0; i < 200; ++i) {
    raw_round_trip(link, frame, seq++, *in, o.busy);
    udp_round_trip(udp, payload, seq++, udp_in, o.busy);
  }
  while (raw_ns.size() + raw_lost < o.frames) {
    for (std::size_t i = 0; i < o.block && raw_ns.size() + raw_lost < o.frames; ++i) {
      const double t = raw_round_trip(link, frame, seq++, *in, o.busy);
      t < 0 ? ++raw_lost : (raw_ns.push_back(t), 0U);
    }
    for (std::size_t i = 0; i < o.block && udp_ns.size() + udp_lost < o.frames; ++i) {
      const double t = udp_round_trip(udp, payload, seq++, udp_in, o.busy);
      t < 0 ? ++udp_lost : (udp_ns.push_back(t), 0U);
    }
  }
  ::close(udp);

  const Summary r = summarise(raw_ns, raw_lost);
  const Summary u = summarise(udp_ns, udp_lost);
  std::printf("bench_ethercat_link_rtt: round trip to an echo process and back, %zu per path, %zu-byte frames/payloads,\n"
              "  alternating in blocks of %zu; waiting %s\n",
              o.frames, o.size, o.block, o.busy ? "by spinning on receive" : "in poll()");
  std::printf("  veth: RawSocketLink on %s (namespace %s) <-> RawSocketLink echo on %s (namespace %s)\n", veth.a().c_str(),
              ns_a.name().c_str(), veth.b().c_str(), ns_b.name().c_str());
  std::printf("  udp:  UDP socket <-> UDP echo on 127.0.0.1 (namespace %s)\n\n", ns_a.name().c_str());
  std::printf("  %-10s %9s %9s %9s %9s %7s\n", "path", "min us", "p50 us", "p99 us", "max us", "lost");
  std::printf("  %-10s %9.1f %9.1f %9.1f %9.1f %7zu\n", "veth raw", r.min, r.p50, r.p99, r.max, r.lost);
  std::printf("  %-10s %9.1f %9.1f %9.1f %9.1f %7zu\n", "udp lo", u.min, u.p50, u.p99, u.max, u.lost);
  const auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
  std::printf("  %-10s %9.2f %9.2f %9.2f %9.2f\n", "veth/udp", ratio(r.min, u.min), ratio(r.p50, u.p50), ratio(r.p99, u.p99),
              ratio(r.max, u.max));
  const auto c = link.counters();
  std::printf("\n  link counters: tx %llu, rx %llu, rx dropped: short %llu, long %llu, EtherType %llu, outgoing %llu, "
              "overflow %llu\n",
              static_cast<unsigned long long>(c.tx_frames), static_cast<unsigned long long>(c.rx_frames),
              static_cast<unsigned long long>(c.rx_too_short), static_cast<unsigned long long>(c.rx_too_long),
              static_cast<unsigned long long>(c.rx_wrong_ethertype), static_cast<unsigned long long>(c.rx_own),
              static_cast<unsigned long long>(c.rx_overflow));
  return 0;
}
