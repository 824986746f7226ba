// Replays a fuzz target without libFuzzer (the g++ builds CI runs, fuzz/README.md): every file of
// the seed corpus, then deterministic pseudo-random mutations of them, so that crashes found once
// stay fixed and the targets keep compiling and running under -Werror and the sanitizers.
//
//   fuzz_replay_<name> CORPUS_DIR [MUTATIONS [SECONDS]]   seeds, then up to MUTATIONS mutants
//   fuzz_replay_<name> FILE                               one input (a crash-* file to reproduce)
//
// The mutation sequence is fixed (one seed); the time bound only cuts it short on slow builds, so
// a run is a prefix of the same sequence everywhere.
#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void run(const Bytes& b) { LLVMFuzzerTestOneInput(b.data(), b.size()); }

// One libFuzzer-like mutation: bit flip, random byte, insert, erase, interesting value, copy of a
// chunk, or a splice with another seed.
Bytes mutate(const Bytes& seed, const std::vector<Bytes>& seeds, std::mt19937& rng) {
  Bytes b = seed;
  const auto pick = [&rng](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
  const std::size_t edits = 1 + pick(4);
  for (std::size_t e = 0; e < edits; ++e) {
    switch (pick(7)) {
      case 0:
        if (!b.empty()) b[pick(b.size())] ^= static_cast<std::uint8_t>(1U << pick(8));
        break;
      case 1:
        if (!b.empty()) b[pick(b.size())] = static_cast<std::uint8_t>(pick(256));
        break;
      case 2:
        b.insert(b.begin() + static_cast<std::ptrdiff_t>(pick(b.size() + 1)), static_cast<std::uint8_t>(pick(256)));
        break;
      case 3:
        if (!b.empty()) {
          const auto at = pick(b.size());
          const auto n = 1 + pick(std::min<std::size_t>(b.size() - at, 16));
          b.erase(b.begin() + static_cast<std::ptrdiff_t>(at), b.begin() + static_cast<std::ptrdiff_t>(at + n));
        }
        break;
      case 4: {  // boundary values parsers compare against
        static constexpr std::uint8_t kInteresting[] = {0x00, 0x01, 0x07, 0x08, 0x09, 0x7F, 0x80, 0xFF, 0xC1, 0xDE, 0xDF};
        if (!b.empty()) b[pick(b.size())] = kInteresting[pick(std::size(kInteresting))];
        break;
      }
      case 5:
        if (!b.empty()) {
          const auto from = pick(b.size());
          const auto n = 1 + pick(std::min<std::size_t>(b.size() - from, 32));
          const Bytes chunk(b.begin() + static_cast<std::ptrdiff_t>(from), b.begin() + static_cast<std::ptrdiff_t>(from + n));
          b.insert(b.begin() + static_cast<std::ptrdiff_t>(pick(b.size() + 1)), chunk.begin(), chunk.end());
        }
        break;
      default: {
        const Bytes& other = seeds[pick(seeds.size())];
        const auto keep = pick(b.size() + 1);
        const auto from = pick(other.size() + 1);
        b.resize(keep);
        b.insert(b.end(), other.begin() + static_cast<std::ptrdiff_t>(from), other.end());
        break;
      }
    }
  }
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR|FILE [MUTATIONS [SECONDS]]\n", argv[0]);
    return 2;
  }
  const std::filesystem::path where = argv[1];
  if (std::filesystem::is_regular_file(where)) {
    run(read_file(where));
    std::printf("ran %s\n", where.c_str());
    return 0;
  }
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(where)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());  // same order on every file system
  if (files.empty()) {
    std::fprintf(stderr, "no seeds in %s\n", where.c_str());
    return 2;
  }
  std::vector<Bytes> seeds;
  std::size_t largest = 0;
  for (const auto& f : files) {
    seeds.push_back(read_file(f));
    largest = std::max(largest, seeds.back().size());
    run(seeds.back());
  }

  const unsigned long mutations = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 20000;
  const double seconds = argc > 3 ? std::strtod(argv[3], nullptr) : 2.0;
  const auto stop = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  std::mt19937 rng(0x5EED);
  // Half the mutants start from a seed, half continue a chain of mutants (which reaches further
  // than single edits); the size cap keeps chains from growing without bound.
  std::vector<Bytes> chains = seeds;
  unsigned long done = 0;
  for (; done < mutations; ++done) {
    // Checking the clock every 64 inputs keeps it out of the cost of small inputs.
    if (done % 64 == 0 && std::chrono::steady_clock::now() > stop) break;
    const std::size_t i = (done / 2) % seeds.size();
    Bytes m = mutate(done % 2 == 0 ? seeds[i] : chains[i], seeds, rng);
    run(m);
    if (m.size() <= 2 * largest + 64) chains[i] = std::move(m);
  }
  std::printf("%zu seeds, %lu mutations\n", seeds.size(), done);
  return 0;
}
