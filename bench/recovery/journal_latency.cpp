// SPDX-License-Identifier: GPL-3.0-or-later
// journal_latency: signal to durable breakpoint record for each way of writing a journal slot
// (O_DIRECT|O_DSYNC, fdatasync, RWF_DSYNC; sync_file_range as a not-durable reference), with and
// without the writer's real-time I/O priority, on a quiet disk or while a load thread streams
// buffered writes of new files to the same file system in bursts; the disk's own counters over the run.
//
//   journal_latency --dir DIR [--records N] [--interval-ms M] [--sync WAY[,WAY]|all]
//                   [--ioprio rt|none|both] [--load-mb MB] [--load-period-s P] [--seed S] [--json]
#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "opencnc/broaching/journal.hpp"

namespace {

using namespace opencnc;
using Clock = std::chrono::steady_clock;

/// The disk's counters (/proc/diskstats) of the device holding a folder.
struct DiskStats {
  double writes = 0, sectors_written = 0, write_ms = 0, flushes = 0, flush_ms = 0;
  int max_inflight_writes = 0;  ///< the most writes the disk held at once (sampled every ms)
};

/// Samples the disk's writes in flight (/sys/dev/block/MAJ:MIN/inflight: dispatched to the driver
/// and not completed) every millisecond, keeping the largest.
class InflightSampler {
 public:
  explicit InflightSampler(dev_t dev)
      : path_(fmt::format("/sys/dev/block/{}:{}/inflight", major(dev), minor(dev))),
        thread_([this] { run(); }) {}
  ~InflightSampler() {
    stop_ = true;
    thread_.join();
  }
  int max_writes() const { return max_; }

 private:
  void run() {
    while (!stop_) {
      std::ifstream in(path_);
      int reads = 0, writes = 0;
      if (in >> reads >> writes) max_ = std::max(max_.load(), writes);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  std::string path_;
  std::atomic<bool> stop_{false};
  std::atomic<int> max_{0};
  std::thread thread_;
};

std::optional<DiskStats> disk_stats(dev_t dev) {
  std::ifstream in("/proc/diskstats");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream f(line);
    unsigned maj = 0, min = 0;
    std::string name;
    std::vector<double> v;
    f >> maj >> min >> name;
    for (double x; f >> x;) v.push_back(x);
    if (maj != major(dev) || min != minor(dev) || v.size() < 17) continue;
    // Fields after the name: 5 writes completed, 7 sectors written, 8 ms writing, 16 flushes
    // completed, 17 ms flushing (Documentation/admin-guide/iostats.rst; counted from 1).
    return DiskStats{v[4], v[6], v[7], v[15], v[16]};
  }
  return std::nullopt;
}

/// A build's writes: every `period_s`, `burst_mb` of new files (8 MiB each, seeded bytes) written
/// through the page cache and then the writeback of all of them started at once
/// (SYNC_FILE_RANGE_WRITE), as the kernel's flusher starts a build's expired dirty pages; the
/// files of two bursts in turn, each recreated.
class Load {
 public:
  Load(std::filesystem::path dir, double burst_mb, double period_s, unsigned seed)
      : dir_(std::move(dir)), burst_mb_(burst_mb), period_s_(period_s), seed_(seed) {
    std::error_code ec;
    if (burst_mb_ > 0 && std::filesystem::create_directories(dir_, ec))
      thread_ = std::thread([this] { run(); });
  }
  ~Load() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  double written_mb() const { return static_cast<double>(written_) / (1 << 20); }

 private:
  static constexpr std::size_t kChunk = 1 << 20, kFile = 8 << 20;
  void run() {
    std::vector<std::uint64_t> chunk(kChunk / 8);
    std::uint64_t x = seed_ | 1;
    const auto burst_bytes = std::max(kChunk, static_cast<std::size_t>(burst_mb_ * (1 << 20)));
    const std::size_t files_per_burst = (burst_bytes + kFile - 1) / kFile;
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s_));
    std::size_t file = 0;
    for (auto next = Clock::now(); !stop_; next += period) {
      while (!stop_ && Clock::now() < next) std::this_thread::sleep_for(std::chrono::milliseconds(5));
      std::vector<int> fds;  // this burst's files, their writeback started together
      std::size_t in_burst = 0, in_file = kFile;
      while (!stop_ && in_burst < burst_bytes) {
        if (in_file == kFile) {
          const auto path = dir_ / fmt::format("load-{}.bin", file++ % (2 * files_per_burst));
          ::unlink(path.c_str());  // a new file each time, as a build writes its objects
          fds.push_back(::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
          in_file = 0;
          if (fds.back() < 0) return;
        }
        for (auto& w : chunk) {  // xorshift64: incompressible, the same every run
          x ^= x << 13;
          x ^= x >> 7;
          x ^= x << 17;
          w = x;
        }
        if (::pwrite(fds.back(), chunk.data(), kChunk, static_cast<off_t>(in_file)) !=
            static_cast<ssize_t>(kChunk))
          break;
        in_file += kChunk;
        in_burst += kChunk;
        written_ += kChunk;
      }
      for (int fd : fds) {
        ::sync_file_range(fd, 0, 0, SYNC_FILE_RANGE_WRITE);
        ::close(fd);
      }
    }
  }
  std::filesystem::path dir_;
  double burst_mb_, period_s_;
  unsigned seed_;
  std::atomic<bool> stop_{false};
  std::atomic<std::size_t> written_{0};
  std::thread thread_;
};

/// The way a record is written: a journal's, or the reference that skips the device's cache flush.
struct Way {
  std::string name;
  std::optional<recovery::JournalSync> sync;  ///< nullopt: sync_file_range (not durable)
};

/// One slot file written with pwrite + sync_file_range: the data reaches the device, its write
/// cache is not flushed — what the journal's ways cost without the flush, not a durable record.
class SyncFileRangeSlot {
 public:
  explicit SyncFileRangeSlot(const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    fd_ = ::open((dir / "slot.bin").c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
    block_.assign(recovery::Journal::kBlockBytes, std::byte{0});
    if (fd_ >= 0 && (::pwrite(fd_, block_.data(), block_.size(), 0) < 0 || ::fsync(fd_) != 0)) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  ~SyncFileRangeSlot() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }
  bool write(std::span<const std::byte> payload) {
    std::copy(payload.begin(), payload.end(), block_.begin());
    return ::pwrite(fd_, block_.data(), block_.size(), 0) == static_cast<ssize_t>(block_.size()) &&
           ::sync_file_range(
               fd_, 0, static_cast<off_t>(block_.size()),
               SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE | SYNC_FILE_RANGE_WAIT_AFTER) == 0;
  }

 private:
  int fd_ = -1;
  std::vector<std::byte> block_;
};

struct Options {
  std::filesystem::path dir;
  int records = 200;
  double interval_ms = 20;
  std::vector<Way> ways;
  std::vector<bool> ioprio = {true, false};
  double load_mb = 0;        ///< MB of new files written in each burst beside the records
  double load_period_s = 5;  ///< seconds from one burst to the next
  unsigned seed = 20261126;
  bool json = false;
};

struct Result {
  std::string way, how;
  bool rt_io = false, rt_io_granted = false, fifo = false, durable = true;
  std::vector<double> ms;
  std::string error;
};

double rank(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0;
  const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size())));
  return sorted[std::max<std::size_t>(k, 1) - 1];
}

/// One way of writing under test: its journal (or the reference slot) and its writer thread, run
/// as the journal feature runs its own (SCHED_FIFO 70 where permitted, the I/O priority as asked);
/// a record handed to it at a "signal", timed until it is durable.
class Writer {
 public:
  Writer(const std::filesystem::path& root, const Way& way, bool rt_io, unsigned seed) : bytes_(seed) {
    res_.way = way.name;
    res_.rt_io = rt_io;
    res_.durable = way.sync.has_value();
    dir_ = root / fmt::format("jl-{}-{}", way.name, rt_io ? "rt" : "be");
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
    if (way.sync) {
      journal_ = recovery::Journal::open(dir_.string(), &res_.error, {*way.sync});
      if (journal_) res_.how = journal_->how();
    } else {
      sfr_ = std::make_unique<SyncFileRangeSlot>(dir_);
      if (!sfr_->ok()) res_.error = "cannot create " + dir_.string();
      res_.how = "pwrite + sync_file_range (no cache flush: not durable)";
    }
    thread_ = std::thread([this] { loop(); });
  }
  ~Writer() {
    {
      std::lock_guard lock(m_);
      quit_ = true;
    }
    cv_.notify_all();
    thread_.join();
    journal_.reset();
    sfr_.reset();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  /// Hands a record over at `signal` and waits until it is durable (or failed).
  void record(Clock::time_point signal) {
    std::unique_lock lock(m_);
    signal_ = signal;
    cv_.notify_all();
    cv_.wait(lock, [&] { return !signal_.has_value(); });
  }
  /// The figures (latencies sorted). After the last record().
  Result result() {
    std::lock_guard lock(m_);
    Result r = res_;
    std::sort(r.ms.begin(), r.ms.end());
    return r;
  }

 private:
  void loop() {
    sched_param p{};
    p.sched_priority = 70;
    const bool fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
    const bool granted = res_.rt_io && recovery::raise_io_priority();
    std::vector<std::byte> record(600);  // a breakpoint record's size
    std::unique_lock lock(m_);
    res_.fifo = fifo;
    res_.rt_io_granted = granted;
    for (;;) {
      cv_.wait(lock, [&] { return quit_ || signal_.has_value(); });
      if (quit_) return;
      const Clock::time_point t0 = *signal_;
      lock.unlock();
      for (auto& b : record) b = static_cast<std::byte>(bytes_() & 0xFF);
      std::string error;
      bool ok = false;
      if (journal_) ok = journal_->write(record, &error);
      if (sfr_ && sfr_->ok()) ok = sfr_->write(record);
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      lock.lock();
      if (ok) res_.ms.push_back(ms);
      if (!ok && res_.error.empty()) res_.error = error.empty() ? "write failed" : error;
      signal_.reset();
      cv_.notify_all();
    }
  }

  std::filesystem::path dir_;
  std::unique_ptr<recovery::Journal> journal_;
  std::unique_ptr<SyncFileRangeSlot> sfr_;
  std::mt19937 bytes_;
  std::mutex m_;
  std::condition_variable cv_;
  std::optional<Clock::time_point> signal_;
  bool quit_ = false;
  Result res_;
  std::thread thread_;
};

/// Every way measured in the same stretch of time: in each round every writer gets one record,
/// in a seeded random order, a seeded random gap before each, so that whatever else the disk does
/// falls on all of them alike. The disk's counters cover the whole run (all ways and the load).
std::vector<Result> measure(const Options& o, std::optional<DiskStats>& disk, double& load_mb) {
  std::vector<std::unique_ptr<Writer>> writers;
  unsigned k = 0;
  for (const Way& way : o.ways) {
    for (bool rt_io : o.ioprio) writers.push_back(std::make_unique<Writer>(o.dir, way, rt_io, o.seed + ++k));
  }
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> gap(0, 2 * o.interval_ms);
  std::vector<std::size_t> order(writers.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  struct stat st {};
  ::stat(o.dir.c_str(), &st);
  {
    // The first burst goes a second ahead, so its writeback is under way when the records begin.
    Load load(o.dir / "jl-load", o.load_mb, o.load_period_s, o.seed);
    if (o.load_mb > 0) std::this_thread::sleep_for(std::chrono::seconds(1));
    const std::optional<DiskStats> before = disk_stats(st.st_dev);
    InflightSampler inflight(st.st_dev);
    for (int round = 0; round < o.records; ++round) {
      std::shuffle(order.begin(), order.end(), rng);
      for (std::size_t w : order) {
        std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(gap(rng)));
        writers[w]->record(Clock::now());
      }
    }
    const std::optional<DiskStats> after = disk_stats(st.st_dev);
    if (before && after) {
      disk = DiskStats{after->writes - before->writes,     after->sectors_written - before->sectors_written,
                       after->write_ms - before->write_ms, after->flushes - before->flushes,
                       after->flush_ms - before->flush_ms, inflight.max_writes()};
    }
    load_mb = load.written_mb();
  }
  std::vector<Result> results;
  for (auto& w : writers) results.push_back(w->result());
  return results;
}

int usage(int rc) {
  fmt::print(rc == 0 ? stdout : stderr,
             "usage: journal_latency --dir DIR [--records N] [--interval-ms M] [--sync WAY[,WAY]|all]\n"
             "                       [--ioprio rt|none|both] [--load-mb MB] [--load-period-s P] [--seed S] "
             "[--json]\n"
             "  signal to durable breakpoint record (p50/p99/max) for each way of writing a slot, in DIR\n"
             "  (the file system under test; created; only this program's jl-* folders may be in it)\n"
             "  WAY: direct (O_DIRECT|O_DSYNC), fdatasync, dsync (RWF_DSYNC), sync-file-range (not\n"
             "  durable: no cache flush; a reference); a comma-separated list; all: each (default)\n"
             "  --ioprio: the writer's I/O priority real-time class, the default, or each (default both)\n"
             "  --load-mb: MB of new files written to DIR's file system, their writeback started at once,\n"
             "  every --load-period-s seconds (default 5) while the records are written (default 0: none)\n"
             "  --interval-ms: mean gap between records (uniform 0..2M, seeded; default 20)\n");
  return rc;
}

std::optional<Way> way_named(std::string_view s) {
  if (s == "direct") return Way{"direct", recovery::JournalSync::Direct};
  if (s == "fdatasync") return Way{"fdatasync", recovery::JournalSync::Fdatasync};
  if (s == "dsync") return Way{"dsync", recovery::JournalSync::Dsync};
  if (s == "sync-file-range") return Way{"sync-file-range", std::nullopt};
  return std::nullopt;
}

/// Parses the command line; nullopt after printing why (or the help: `rc` 0).
std::optional<Options> parse(int argc, char** argv, int& rc) {
  Options o;
  std::string sync = "all", ioprio = "both";
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--help" || a == "-h") {
      rc = usage(0);
      return std::nullopt;
    }
    const bool valued = a == "--dir" || a == "--records" || a == "--interval-ms" || a == "--sync" ||
                        a == "--ioprio" || a == "--load-mb" || a == "--load-period-s" || a == "--seed";
    if (a == "--json") {
      o.json = true;
    } else if (valued && i + 1 < argc) {
      const char* v = argv[++i];
      if (a == "--dir") o.dir = v;
      if (a == "--records") o.records = std::max(1, std::atoi(v));
      if (a == "--interval-ms") o.interval_ms = std::max(0.0, std::atof(v));
      if (a == "--sync") sync = v;
      if (a == "--ioprio") ioprio = v;
      if (a == "--load-mb") o.load_mb = std::max(0.0, std::atof(v));
      if (a == "--load-period-s") o.load_period_s = std::max(0.1, std::atof(v));
      if (a == "--seed") o.seed = static_cast<unsigned>(std::strtoul(v, nullptr, 10));
    } else {
      fmt::print(stderr, "journal_latency: unknown option or missing value '{}'\n", a);
      rc = usage(2);
      return std::nullopt;
    }
  }
  rc = 2;
  if (o.dir.empty()) {
    fmt::print(stderr, "journal_latency: --dir is required (a folder on the file system to measure)\n");
    return std::nullopt;
  }
  if (sync == "all") sync = "dsync,fdatasync,direct,sync-file-range";
  for (std::size_t at = 0; at <= sync.size();) {  // a comma-separated list
    const std::size_t end = std::min(sync.find(',', at), sync.size());
    const std::optional<Way> way = way_named(std::string_view(sync).substr(at, end - at));
    if (!way) {
      fmt::print(stderr,
                 "journal_latency: --sync {}: dsync, fdatasync, direct, sync-file-range, a list of them, or "
                 "all\n",
                 sync);
      return std::nullopt;
    }
    o.ways.push_back(*way);
    at = end + 1;
  }
  if (ioprio != "rt" && ioprio != "none" && ioprio != "both") {
    fmt::print(stderr, "journal_latency: --ioprio {}: rt, none or both\n", ioprio);
    return std::nullopt;
  }
  o.ioprio = ioprio == "rt"     ? std::vector<bool>{true}
             : ioprio == "none" ? std::vector<bool>{false}
                                : std::vector<bool>{true, false};
  std::error_code ec;
  if (std::filesystem::exists(o.dir, ec)) {
    for (const auto& entry : std::filesystem::directory_iterator(o.dir, ec)) {
      if (!entry.path().filename().string().starts_with("jl-")) {
        fmt::print(stderr, "journal_latency: --dir {} holds {}: choose a folder of its own\n", o.dir.string(),
                   entry.path().filename().string());
        return std::nullopt;
      }
    }
  }
  std::filesystem::create_directories(o.dir, ec);
  if (ec) {
    fmt::print(stderr, "journal_latency: cannot create {}: {}\n", o.dir.string(), ec.message());
    return std::nullopt;
  }
  rc = 0;
  return o;
}

std::string to_json(const Result& r) {
  return fmt::format(
      "{{\"way\": \"{}\", \"how\": \"{}\", \"durable\": {}, \"rt_io\": {}, \"rt_io_granted\": {}, "
      "\"fifo\": {}, \"records\": {}, \"p50_ms\": {:.3f}, \"p99_ms\": {:.3f}, \"max_ms\": {:.3f}, "
      "\"error\": \"{}\"}}",
      r.way, r.how, r.durable, r.rt_io, r.rt_io_granted, r.fifo, r.ms.size(), rank(r.ms, 0.5),
      rank(r.ms, 0.99), r.ms.empty() ? 0 : r.ms.back(), r.error);
}

}  // namespace

int main(int argc, char** argv) {
  int rc = 0;
  const std::optional<Options> o = parse(argc, argv, rc);
  if (!o) return rc;
  std::optional<DiskStats> disk;
  double load_mb = 0;
  const std::vector<Result> results = measure(*o, disk, load_mb);
  bool failed = false;
  for (const Result& r : results) failed = failed || !r.error.empty();
  if (o->json) {
    std::string items;
    for (const Result& r : results) items += (items.empty() ? "" : ", ") + to_json(r);
    std::string d = "null";
    if (disk) {
      d = fmt::format(
          "{{\"writes\": {:.0f}, \"mb_written\": {:.1f}, \"write_ms\": {:.0f}, \"flushes\": {:.0f}, "
          "\"flush_ms\": {:.0f}, \"max_inflight_writes\": {}}}",
          disk->writes, disk->sectors_written * 512 / (1 << 20), disk->write_ms, disk->flushes,
          disk->flush_ms, disk->max_inflight_writes);
    }
    fmt::print(
        "{{\"dir\": \"{}\", \"records\": {}, \"interval_ms\": {}, \"load_mb_per_burst\": {}, "
        "\"load_period_s\": {}, \"load_mb_written\": {:.0f}, \"seed\": {}, "
        "\"disk\": {}, \"results\": [{}]}}\n",
        o->dir.string(), o->records, o->interval_ms, o->load_mb, o->load_period_s, load_mb, o->seed, d,
        items);
    return failed ? 1 : 0;
  }
  for (const Result& r : results) {
    fmt::print("{:16} io {:3} records {:4}  p50 {:7.3f}  p99 {:7.3f}  max {:7.3f} ms{}\n", r.way,
               !r.rt_io          ? "be"
               : r.rt_io_granted ? "rt"
                                 : "rt?",
               r.ms.size(), rank(r.ms, 0.5), rank(r.ms, 0.99), r.ms.empty() ? 0 : r.ms.back(),
               r.error.empty() ? "" : "  error: " + r.error);
  }
  if (disk) {
    fmt::print(
        "load {:.0f} MB written; the disk during the run: {:.0f} writes, {:.1f} MB, {:.0f} ms writing, "
        "{:.0f} flushes ({:.0f} ms), at most {} writes in flight\n",
        load_mb, disk->writes, disk->sectors_written * 512 / (1 << 20), disk->write_ms, disk->flushes,
        disk->flush_ms, disk->max_inflight_writes);
  }
  return failed ? 1 : 0;
}
