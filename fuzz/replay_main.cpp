// Replay driver for the fuzz targets (docs/adr/0012-fuzz-smoke-in-ci.md). libFuzzer needs clang,
// and a clang build of every module takes ~20 minutes on CI's two cores; this driver lets the
// ordinary g++ builds (release and the AddressSanitizer + UBSan one) run the very same
// LLVMFuzzerTestOneInput of each target as a ctest smoke pass: every committed seed, every
// regression reproducer, and a fixed number of seeded mutations of them (bit flips, interesting
// bytes, inserted and erased ranges, splices, dictionary tokens), so CI exercises each reader on
// broken input on every commit. It is not a coverage-guided fuzzer: the campaigns that find new
// bugs are run with tools/fuzz.sh (libFuzzer); this only makes sure what they found stays fixed
// and that nothing obvious breaks. The mutator is a few lines and written here because no Debian
// package offers a standalone one for g++ (LLVM's StandaloneFuzzTargetMain.c, which only
// replays, is not packaged either).
//
//   fuzz_replay_<name> [--mutations N] [--seed S] [--dict FILE] [--crash-dir DIR] PATH...
//
// PATHs are files or folders (read non-recursively, sorted). Before each mutated input runs it is
// written to DIR/last-input (default: the working folder), so a crash leaves its reproducer.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

using Bytes = std::string;

Bytes read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

// splitmix64: a fixed, portable sequence for a seed (std:: distributions differ between
// standard libraries).
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return n ? std::size_t(next() % n) : 0; }
};

// libFuzzer dictionary lines: name="value" or "value", with \\, \" and \xNN escapes.
std::vector<Bytes> read_dict(const std::filesystem::path& p) {
  std::vector<Bytes> out;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) {
    const auto q0 = line.find('"');
    const auto q1 = line.rfind('"');
    if (line.empty() || line[0] == '#' || q0 == std::string::npos || q1 <= q0) continue;
    Bytes tok;
    for (std::size_t i = q0 + 1; i < q1; ++i) {
      if (line[i] == '\\' && i + 1 < q1) {
        if (line[i + 1] == 'x' && i + 3 < q1) {
          tok += char(std::stoi(line.substr(i + 2, 2), nullptr, 16));
          i += 3;
        } else {
          tok += line[++i];
        }
      } else {
        tok += line[i];
      }
    }
    if (!tok.empty()) out.push_back(tok);
  }
  return out;
}

Bytes mutate(Bytes b, const std::vector<Bytes>& corpus, const std::vector<Bytes>& dict, Rng& rng) {
  static const uint8_t kInteresting[] = {0,   1,   0x7f, 0x80, 0xff, '0', '9', '-', '.',
                                         'e', ' ', '\n', '"',  '[',  '{', '}', ']'};
  const int n = 1 + int(rng.below(4));
  for (int k = 0; k < n; ++k) {
    const std::size_t at = rng.below(b.size() + 1);
    switch (rng.below(7)) {
      case 0:  // flip a bit
        if (!b.empty()) b[rng.below(b.size())] ^= char(1u << rng.below(8));
        break;
      case 1:  // an interesting byte
        if (!b.empty()) b[rng.below(b.size())] = char(kInteresting[rng.below(sizeof kInteresting)]);
        break;
      case 2:  // insert random bytes
        b.insert(at, Bytes(1 + rng.below(8), char(rng.next())));
        break;
      case 3:  // erase a range
        if (!b.empty())
          b.erase(rng.below(b.size()), 1 + rng.below(std::max<std::size_t>(1, b.size() / 8)));
        break;
      case 4:  // duplicate a range
        if (!b.empty()) {
          const std::size_t from = rng.below(b.size());
          const std::size_t len = 1 + rng.below(std::min<std::size_t>(64, b.size() - from));
          b.insert(at, b.substr(from, len));
        }
        break;
      case 5:  // splice with another input
        if (!corpus.empty()) {
          const Bytes& o = corpus[rng.below(corpus.size())];
          const std::size_t from = rng.below(o.size() + 1);
          b = b.substr(0, at) + o.substr(from);
        }
        break;
      default:  // a dictionary token
        if (!dict.empty()) b.insert(at, dict[rng.below(dict.size())]);
        break;
    }
  }
  if (b.size() > (1u << 20)) b.resize(1u << 20);
  return b;
}

void run(const Bytes& b) {
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(b.data()), b.size());
}

int usage(const char* msg) {
  std::fprintf(stderr,
               "fuzz replay: %s\nusage: fuzz_replay_<name> [--mutations N] [--seed S] "
               "[--dict FILE] [--crash-dir DIR] PATH...\n",
               msg);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  long long mutations = 0;
  uint64_t seed = 1;
  std::filesystem::path dict_path, crash_dir = ".";
  std::vector<std::filesystem::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--mutations" && has_value) {
      mutations = std::atoll(argv[++i]);
    } else if (a == "--seed" && has_value) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (a == "--dict" && has_value) {
      dict_path = argv[++i];
    } else if (a == "--crash-dir" && has_value) {
      crash_dir = argv[++i];
    } else if (!a.empty() && a[0] == '-') {
      return usage(("unknown option " + a).c_str());
    } else {
      inputs.emplace_back(a);
    }
  }
  if (inputs.empty()) return usage("no input files or folders");
  std::vector<std::filesystem::path> files;
  for (const auto& p : inputs) {
    if (std::filesystem::is_directory(p)) {
      for (const auto& e : std::filesystem::directory_iterator(p))
        if (e.is_regular_file()) files.push_back(e.path());
    } else if (std::filesystem::is_regular_file(p)) {
      files.push_back(p);
    } else {
      return usage(("no such file or folder: " + p.string()).c_str());
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<Bytes> corpus;
  for (const auto& f : files) {
    corpus.push_back(read_all(f));
    run(corpus.back());  // a crash here names no file: the one printed last is it
    std::fprintf(stderr, "ran %s\n", f.c_str());
  }
  const std::vector<Bytes> dict = dict_path.empty() ? std::vector<Bytes>{} : read_dict(dict_path);
  std::filesystem::create_directories(crash_dir);
  const auto last = crash_dir / "last-input";
  Rng rng{seed};
  for (long long k = 0; k < mutations; ++k) {
    const Bytes in = mutate(corpus[rng.below(corpus.size())], corpus, dict, rng);
    {
      std::ofstream out(last, std::ios::binary | std::ios::trunc);
      out.write(in.data(), std::streamsize(in.size()));
    }
    run(in);
  }
  std::filesystem::remove(last);
  std::printf(
      "fuzz replay: %zu files and %lld mutations (seed %llu, %zu dictionary tokens): no "
      "crash\n",
      files.size(), mutations, (unsigned long long)seed, dict.size());
  return 0;
}
