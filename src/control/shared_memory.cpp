// SPDX-License-Identifier: GPL-3.0-or-later
// POSIX shared memory for the servo's channels: create, attach with layout checks, the set-up
// hand-over.
#include "opencnc/control/shared_memory.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <new>
#include <utility>

#ifndef OPENCNC_SHARED_HEADERS_HASH
#error "the build defines OPENCNC_SHARED_HEADERS_HASH (src/control/CMakeLists.txt)"
#endif

namespace opencnc::control {
namespace {

constexpr std::uint64_t mix(std::uint64_t h, std::uint64_t v) noexcept {
  for (int i = 0; i < 8; ++i) {
    h ^= (v >> (8 * i)) & 0xffu;
    h *= 0x100000001b3ULL;  // FNV-1a
  }
  return h;
}

bool valid_name(const std::string& name, std::string& error) {
  if (name.size() < 2 || name.size() > 200 || name[0] != '/' || name.find('/', 1) != std::string::npos) {
    error = "shared memory name '" + name + "' must be one '/' followed by up to 199 characters without '/'";
    return false;
  }
  return true;
}

std::string os_error(const std::string& what, const std::string& name) {
  return what + " " + name + ": " + std::strerror(errno);
}

}  // namespace

std::uint64_t shared_layout_id() noexcept {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const std::uint64_t v :
       {std::uint64_t{kSharedLayoutRevision}, std::uint64_t{sizeof(SharedSegment)},
        std::uint64_t{alignof(SharedSegment)}, std::uint64_t{sizeof(SharedHeader)},
        std::uint64_t{sizeof(SharedSetup)}, std::uint64_t{sizeof(ServoConfig)},
        std::uint64_t{sizeof(ServoChannels)}, std::uint64_t{sizeof(Command)},
        std::uint64_t{sizeof(ServoEvent)}, std::uint64_t{sizeof(ServoStatus)},
        std::uint64_t{sizeof(TraceSample)}, std::uint64_t{sizeof(MachineAction)},
        std::uint64_t{sizeof(traj::MotionBlock)}, std::uint64_t{sizeof(machine::MachineCapabilities)},
        std::uint64_t{offsetof(SharedSegment, setup)}, std::uint64_t{offsetof(SharedSegment, channels)}}) {
    h = mix(h, v);
  }
  for (const char* p = OPENCNC_SHARED_HEADERS_HASH; *p != '\0'; ++p)
    h = mix(h, static_cast<unsigned char>(*p));
  return h;
}

std::unique_ptr<SegmentMapping> SegmentMapping::create(const std::string& name, std::int64_t period_ns,
                                                       std::uint32_t heartbeat_timeout_ticks,
                                                       std::string& error) {
  if (!valid_name(name, error)) return nullptr;
  ::shm_unlink(name.c_str());  // a stale segment of a previous run (ENOENT otherwise)
  const int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT | O_EXCL, 0660);
  if (fd < 0) {
    error = os_error("cannot create shared memory", name);
    return nullptr;
  }
  void* p = MAP_FAILED;
  if (::ftruncate(fd, static_cast<off_t>(sizeof(SharedSegment))) == 0) {
    p = ::mmap(nullptr, sizeof(SharedSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  }
  if (p == MAP_FAILED) {
    error = os_error("cannot map shared memory", name);
    ::close(fd);
    ::shm_unlink(name.c_str());
    return nullptr;
  }
  ::close(fd);
  auto* s = new (p) SharedSegment();
  s->header.period_ns = period_ns;
  s->header.heartbeat_timeout_ticks.store(heartbeat_timeout_ticks, std::memory_order_relaxed);
  s->header.size_bytes = sizeof(SharedSegment);
  s->header.layout_id = shared_layout_id();
  s->header.magic = kSharedMagic;  // last: a controller attaching now finds it whole or refuses it
  return std::unique_ptr<SegmentMapping>(new SegmentMapping(name, s, true));
}

std::unique_ptr<SegmentMapping> SegmentMapping::attach(const std::string& name, std::string& error) {
  if (!valid_name(name, error)) return nullptr;
  const int fd = ::shm_open(name.c_str(), O_RDWR, 0);
  if (fd < 0) {
    error = errno == ENOENT ? "no servo tick publishes " + name + " (is the HAL component opencnc_rt loaded?)"
                            : os_error("cannot open shared memory", name);
    return nullptr;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || st.st_size < static_cast<off_t>(sizeof(SharedHeader))) {
    error = "shared memory " + name + " is not an opencnc segment (too small)";
    ::close(fd);
    return nullptr;
  }
  const auto mapped = static_cast<std::size_t>(st.st_size);
  void* p = ::mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) {
    error = os_error("cannot map shared memory", name);
    return nullptr;
  }
  const auto* h = static_cast<const SharedHeader*>(p);
  if (h->magic != kSharedMagic) {
    error = "shared memory " + name + " is not an opencnc segment";
  } else if (h->layout_id != shared_layout_id() || h->size_bytes != sizeof(SharedSegment) ||
             mapped != sizeof(SharedSegment)) {
    error = "the servo tick behind " + name + " was built from another opencnc (layout " +
            std::to_string(h->layout_id) + ", this build " + std::to_string(shared_layout_id()) +
            "): load the opencnc_rt.so of this build";
  }
  if (!error.empty()) {
    ::munmap(p, mapped);
    return nullptr;
  }
  return std::unique_ptr<SegmentMapping>(new SegmentMapping(name, static_cast<SharedSegment*>(p), false));
}

SegmentMapping::~SegmentMapping() {
  if (owner_) {
    segment_->~SharedSegment();
    ::shm_unlink(name_.c_str());
  }
  ::munmap(segment_, sizeof(SharedSegment));
}

std::uint64_t offer_setup(SharedSegment& s, const SharedSetup& setup) noexcept {
  std::memcpy(static_cast<void*>(&s.setup), &setup, sizeof setup);
  return s.header.setup_generation.fetch_add(1, std::memory_order_acq_rel) + 1;
}

bool setup_taken(const SharedSegment& s, std::uint64_t generation) noexcept {
  return s.header.setup_taken.load(std::memory_order_acquire) >= generation;
}

void drain_stale_output(SharedSegment& s) noexcept {
  s.channels.events.drop_until(s.channels.events.popped() + s.channels.events.available());
  s.channels.trace.drop_until(s.channels.trace.popped() + s.channels.trace.available());
}

}  // namespace opencnc::control
