// SPDX-License-Identifier: GPL-3.0-or-later
// opencnc_rt.so — the servo tick as a LinuxCNC HAL real-time component (uspace): creates the pins
// and the shared memory at load time, runs control::SharedServoHost in the HAL thread it is added to.
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <type_traits>

#include "hal.h"
#include "opencnc/control/shared_memory.hpp"
#include "opencnc/control/shared_servo.hpp"
#include "opencnc/hal/hal_machine.hpp"
#include "rtapi.h"
#include "rtapi_app.h"

MODULE_AUTHOR("opencnc");
MODULE_DESCRIPTION("opencnc servo tick: the controller's real-time half as a HAL component");
MODULE_LICENSE("GPL");

// loadrt parameters (global, unmangled: rtapi_app finds them by name).
static int joints = 3;
RTAPI_MP_INT(joints, "joints with pins (1..9)");
static int din = 0;
RTAPI_MP_INT(din, "digital inputs (M66 P), 0..64");
static int dout = 0;
RTAPI_MP_INT(dout, "digital outputs (M62-M65), 0..64");
static int ain = 0;
RTAPI_MP_INT(ain, "analog inputs (M66 E), 0..16");
static int aout = 0;
RTAPI_MP_INT(aout, "analog outputs (M67/M68), 0..16");
static char* shm = nullptr;
RTAPI_MP_STRING(shm, "shared memory name the controller attaches to (default /opencnc)");
static int effort = 0;
RTAPI_MP_INT(effort, "1: the drives' force/torque are netted to joint.N.effort and spindle.torque");
static int heartbeat_ms = 100;
RTAPI_MP_INT(heartbeat_ms, "the controller's heartbeat may stop this long before the machine stops");

namespace {

namespace hal = opencnc::hal;
namespace control = opencnc::control;

static_assert(std::is_same_v<hal::Bit, hal_bit_t> && std::is_same_v<hal::S32, hal_s32_t>);
// hal_float_t carries an alignment attribute a template argument drops: compare what matters.
static_assert(sizeof(hal_float_t) == sizeof(hal::Float) && alignof(hal_float_t) == alignof(hal::Float));

/// The status pins beside the machine's (opencnc.<name>).
struct StatusPins {
  hal_bit_t* controller_alive;  ///< out: a controller's heartbeat is fresh
  hal_bit_t* running;           ///< out: a set-up has been taken and the servo runs
  hal_s32_t* heartbeat_losses;  ///< out
};

struct Component {
  int comp_id = -1;
  hal::MachinePins* pins = nullptr;  // in HAL shared memory (halcmd relinks the pointers)
  StatusPins* status = nullptr;
  std::unique_ptr<control::SegmentMapping> segment;
  std::unique_ptr<hal::HalMachine> machine;
  std::unique_ptr<control::SharedServoHost> host;  // built before the thread runs
  bool period_known = false;
};

Component* g_component = nullptr;

int bit(hal_pin_dir_t dir, hal_bit_t** p, int id, const char* name) {
  return hal_pin_bit_newf(dir, p, id, "opencnc.%s", name);
}
int flt(hal_pin_dir_t dir, hal_float_t** p, int id, const char* name) {
  return hal_pin_float_newf(dir, p, id, "opencnc.%s", name);
}
int s32(hal_pin_dir_t dir, hal_s32_t** p, int id, const char* name) {
  return hal_pin_s32_newf(dir, p, id, "opencnc.%s", name);
}

int make_joint_pins(hal::JointPins& p, int j, int id) {
  char n[64];
  int r = 0;
  auto name = [&](const char* what) {
    std::snprintf(n, sizeof n, "joint.%d.%s", j, what);
    return n;
  };
  r |= flt(HAL_OUT, &p.pos_cmd, id, name("pos-cmd"));
  r |= flt(HAL_OUT, &p.vel_cmd, id, name("vel-cmd"));
  r |= s32(HAL_OUT, &p.step_cmd, id, name("step-cmd"));
  r |= flt(HAL_IN, &p.pos_fb, id, name("pos-fb"));
  r |= bit(HAL_OUT, &p.enable, id, name("enable"));
  r |= bit(HAL_IN, &p.amp_fault, id, name("amp-fault"));
  r |= bit(HAL_IN, &p.home_sw, id, name("home-sw"));
  r |= bit(HAL_IN, &p.limit_min, id, name("limit-min"));
  r |= bit(HAL_IN, &p.limit_max, id, name("limit-max"));
  r |= bit(HAL_IO, &p.index_enable, id, name("index-enable"));
  r |= flt(HAL_IN, &p.effort, id, name("effort"));
  return r;
}

int make_machine_pins(hal::MachinePins& p, int id) {
  int r = 0;
  for (int j = 0; j < joints; ++j) r |= make_joint_pins(p.joints[static_cast<std::size_t>(j)], j, id);
  r |= bit(HAL_IN, &p.estop_in, id, "estop-in");
  r |= bit(HAL_OUT, &p.estop_out, id, "estop-out");
  r |= bit(HAL_IN, &p.power_fail, id, "power-fail");
  r |= bit(HAL_IN, &p.probe_in, id, "probe-in");
  r |= flt(HAL_OUT, &p.spindle_speed_out, id, "spindle.speed-out");
  r |= bit(HAL_OUT, &p.spindle_on, id, "spindle.on");
  r |= bit(HAL_OUT, &p.spindle_forward, id, "spindle.forward");
  r |= bit(HAL_OUT, &p.spindle_reverse, id, "spindle.reverse");
  r |= bit(HAL_OUT, &p.spindle_orient, id, "spindle.orient");
  r |= flt(HAL_OUT, &p.spindle_orient_angle, id, "spindle.orient-angle");
  r |= flt(HAL_IN, &p.spindle_speed_in, id, "spindle.speed-in");
  r |= flt(HAL_IN, &p.spindle_revs, id, "spindle.revs");
  r |= bit(HAL_IN, &p.spindle_at_speed, id, "spindle.at-speed");
  r |= bit(HAL_IN, &p.spindle_orient_done, id, "spindle.orient-done");
  r |= bit(HAL_IN, &p.spindle_fault, id, "spindle.fault");
  r |= flt(HAL_IN, &p.spindle_torque, id, "spindle.torque");
  r |= bit(HAL_OUT, &p.flood, id, "coolant-flood");
  r |= bit(HAL_OUT, &p.mist, id, "coolant-mist");
  r |= s32(HAL_OUT, &p.tool_prepare_number, id, "tool.prep-number");
  r |= bit(HAL_OUT, &p.tool_prepare, id, "tool.prepare");
  r |= bit(HAL_OUT, &p.tool_change, id, "tool.change");
  r |= bit(HAL_IN, &p.tool_prepared, id, "tool.prepared");
  r |= bit(HAL_IN, &p.tool_changed, id, "tool.changed");
  r |= s32(HAL_IN, &p.handwheel_counts, id, "handwheel.counts");
  char n[64];
  for (int i = 0; i < din; ++i) {
    std::snprintf(n, sizeof n, "digital-in-%02d", i);
    r |= bit(HAL_IN, &p.digital_in[static_cast<std::size_t>(i)], id, n);
  }
  for (int i = 0; i < dout; ++i) {
    std::snprintf(n, sizeof n, "digital-out-%02d", i);
    r |= bit(HAL_OUT, &p.digital_out[static_cast<std::size_t>(i)], id, n);
  }
  for (int i = 0; i < ain; ++i) {
    std::snprintf(n, sizeof n, "analog-in-%02d", i);
    r |= flt(HAL_IN, &p.analog_in[static_cast<std::size_t>(i)], id, n);
  }
  for (int i = 0; i < aout; ++i) {
    std::snprintf(n, sizeof n, "analog-out-%02d", i);
    r |= flt(HAL_OUT, &p.analog_out[static_cast<std::size_t>(i)], id, n);
  }
  p.joint_count = joints;
  p.digital_inputs = din;
  p.digital_outputs = dout;
  p.analog_inputs = ain;
  p.analog_outputs = aout;
  p.effort_wired = effort != 0;
  return r;
}

int make_status_pins(StatusPins& s, int id) {
  int r = bit(HAL_OUT, &s.controller_alive, id, "controller-alive");
  r |= bit(HAL_OUT, &s.running, id, "running");
  r |= s32(HAL_OUT, &s.heartbeat_losses, id, "heartbeat-losses");
  return r;
}

// The HAL thread's function: one servo period. Real-time: no allocation (the host and the servo
// live in memory set up at load time), no locks, no I/O.
void update(void* arg, long period_ns) {
  auto* c = static_cast<Component*>(arg);
  control::SharedHeader& h = c->segment->segment().header;
  if (!c->period_known) {
    // The period is the thread's, known at its first call: it sets the heartbeat's timeout.
    h.period_ns = period_ns;
    const long ticks = (static_cast<long>(heartbeat_ms) * 1'000'000L + period_ns - 1) / period_ns;
    h.heartbeat_timeout_ticks.store(static_cast<std::uint32_t>(ticks < 1 ? 1 : ticks));
    c->machine->set_period_ns(period_ns);
    c->host->set_heartbeat_timeout(static_cast<std::uint32_t>(ticks < 1 ? 1 : ticks));
    c->period_known = true;
  }
  c->host->tick();
  *c->status->controller_alive = h.controller_alive.load(std::memory_order_relaxed);
  *c->status->running = c->host->running();
  *c->status->heartbeat_losses = static_cast<rtapi_s32>(h.heartbeat_losses.load(std::memory_order_relaxed));
}

bool params_ok() {
  if (joints < 1 || joints > opencnc::machine::kMaxJoints || din < 0 ||
      din > opencnc::machine::kDigitalChannels || dout < 0 || dout > opencnc::machine::kDigitalChannels ||
      ain < 0 || ain > opencnc::machine::kAnalogChannels || aout < 0 ||
      aout > opencnc::machine::kAnalogChannels || heartbeat_ms < 1 || effort < 0 || effort > 1) {
    rtapi_print_msg(
        RTAPI_MSG_ERR,
        "opencnc_rt: joints must be 1..9, din/dout 0..64, ain/aout 0..16, heartbeat_ms >= 1, effort 0 or 1 "
        "(got joints=%d din=%d dout=%d ain=%d aout=%d heartbeat_ms=%d effort=%d)\n",
        joints, din, dout, ain, aout, heartbeat_ms, effort);
    return false;
  }
  return true;
}

int fail(Component* c, const char* what) {
  rtapi_print_msg(RTAPI_MSG_ERR, "opencnc_rt: %s\n", what);
  hal_exit(c->comp_id);
  delete c;
  return -1;
}

}  // namespace

extern "C" int rtapi_app_main(void) {
  if (!params_ok()) return -1;
  auto* c = new (std::nothrow) Component();
  if (c == nullptr) return -1;
  c->comp_id = hal_init("opencnc_rt");  // the module's name: loadrt waits for it
  if (c->comp_id < 0) {
    const int error = c->comp_id;
    delete c;
    return error;
  }
  c->pins = static_cast<hal::MachinePins*>(hal_malloc(sizeof(hal::MachinePins)));
  c->status = static_cast<StatusPins*>(hal_malloc(sizeof(StatusPins)));
  if (c->pins == nullptr || c->status == nullptr) return fail(c, "out of HAL memory");
  new (c->pins) hal::MachinePins();
  if (make_machine_pins(*c->pins, c->comp_id) != 0 || make_status_pins(*c->status, c->comp_id) != 0)
    return fail(c, "cannot create the pins");
  std::string error;
  const std::string name = shm != nullptr && shm[0] != '\0' ? shm : "/opencnc";
  c->segment = control::SegmentMapping::create(name, 0, 1, error);
  if (!c->segment) return fail(c, error.c_str());
  c->machine = std::make_unique<hal::HalMachine>(*c->pins);
  c->host = std::make_unique<control::SharedServoHost>(c->segment->segment(), *c->machine);
  if (hal_export_funct("opencnc.update", update, c, 1, 0, c->comp_id) != 0)
    return fail(c, "cannot export opencnc.update");
  g_component = c;
  rtapi_print_msg(RTAPI_MSG_INFO, "opencnc_rt: %d joints, shared memory %s, heartbeat %d ms\n", joints,
                  name.c_str(), heartbeat_ms);
  return hal_ready(c->comp_id);
}

extern "C" void rtapi_app_exit(void) {
  Component* c = g_component;
  g_component = nullptr;
  if (c == nullptr) return;
  const int id = c->comp_id;
  delete c;  // the host, then the segment (unlinked: a controller still attached keeps its mapping)
  hal_exit(id);
}
