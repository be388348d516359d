// SPDX-License-Identifier: GPL-3.0-or-later
// Rs274Printer — prints canonical calls in the text format of LinuxCNC's `rs274 -g`.
#pragma once

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>

#include "opencnc/canon/sink.hpp"

namespace opencnc::canon {

/// Writes `    7 N..... STRAIGHT_FEED(1.0000, ...)` lines, byte-compatible with LinuxCNC 2.9's
/// standalone interpreter, to a FILE (buffered internally; call flush() at the end).
/// `(PRINT,...)` text goes to `print_stream` unnumbered; rs274 writes it to stdout, in order
/// with the calls (pass the same stream as `out` for that). Non-real-time.
class Rs274Printer final : public Sink {
 public:
  explicit Rs274Printer(std::FILE* out, std::FILE* print_stream = stdout);
  ~Rs274Printer() override;
  Rs274Printer(const Rs274Printer&) = delete;
  Rs274Printer& operator=(const Rs274Printer&) = delete;

  /// Writes buffered text to the stream.
  void flush();
  /// Number of lines printed so far.
  int lines() const noexcept { return sequence_ - 1; }

  void begin_block(const BlockOrigin& origin) override { origin_ = origin; }
  void use_length_units(Units u) override;
  void set_g5x_offset(int index, const Pose& offset) override;
  void set_g92_offset(const Pose& offset) override;
  void set_xy_rotation(double degrees) override;
  void select_plane(Plane p) override;
  void set_feed_reference(FeedReference r) override;

  void straight_traverse(SegmentId, const Pose& end) override { pose_call("STRAIGHT_TRAVERSE(", end); }
  void straight_feed(SegmentId, const Pose& end) override { pose_call("STRAIGHT_FEED(", end); }
  void arc_feed(SegmentId, const ArcFeed& arc) override;
  void straight_probe(SegmentId, const Pose& end) override { pose_call("STRAIGHT_PROBE(", end); }
  void rigid_tap(SegmentId, const Pose& end, double scale) override;
  void nurbs_feed(SegmentId, int order, std::span<const NurbsPoint> points) override;
  void dwell(double seconds) override;

  void set_feed_rate(double rate) override;
  void set_feed_mode(int spindle, FeedMode mode) override;
  void set_motion_control_mode(MotionControl mode, double tolerance) override;
  void set_naivecam_tolerance(double tolerance) override;
  void start_speed_feed_synch(int spindle, double feed_per_rev, bool velocity_mode) override;
  void stop_speed_feed_synch() override { simple("STOP_SPEED_FEED_SYNCH()"); }

  void set_spindle_speed(int spindle, double rpm) override;
  void start_spindle_clockwise(int spindle) override { indexed("START_SPINDLE_CLOCKWISE(", spindle); }
  void start_spindle_counterclockwise(int spindle) override { indexed("START_SPINDLE_COUNTERCLOCKWISE(", spindle); }
  void stop_spindle_turning(int spindle) override { indexed("STOP_SPINDLE_TURNING(", spindle); }
  void set_spindle_mode(int spindle, double css_max) override;
  void orient_spindle(int spindle, double degrees, int direction) override;
  void wait_spindle_orient_complete(int spindle, double timeout_s) override;

  void select_tool(int tool) override { indexed("SELECT_TOOL(", tool); }
  void start_change() override { simple("START_CHANGE()"); }
  void change_tool(int tool) override { indexed("CHANGE_TOOL(", tool); }
  void change_tool_number(int tool) override { indexed("CHANGE_TOOL_NUMBER(", tool); }
  void use_tool_length_offset(const Pose& offset) override;
  void set_tool_table_entry(int index, int tool, const Pose& offset, double diameter, double front_angle,
                            double back_angle, int orientation) override;

  void mist_on() override { simple("MIST_ON()"); }
  void mist_off() override { simple("MIST_OFF()"); }
  void flood_on() override { simple("FLOOD_ON()"); }
  void flood_off() override { simple("FLOOD_OFF()"); }

  void enable_feed_override() override { simple("ENABLE_FEED_OVERRIDE()"); }
  void disable_feed_override() override { simple("DISABLE_FEED_OVERRIDE()"); }
  void enable_speed_override(int spindle) override { indexed("ENABLE_SPEED_OVERRIDE(", spindle); }
  void disable_speed_override(int spindle) override { indexed("DISABLE_SPEED_OVERRIDE(", spindle); }
  void enable_adaptive_feed() override { simple("ENABLE_ADAPTIVE_FEED()"); }
  void disable_adaptive_feed() override { simple("DISABLE_ADAPTIVE_FEED()"); }
  void enable_feed_hold() override { simple("ENABLE_FEED_HOLD()"); }
  void disable_feed_hold() override { simple("DISABLE_FEED_HOLD()"); }

  void set_motion_output_bit(int index) override { indexed("SET_MOTION_OUTPUT_BIT(", index); }
  void clear_motion_output_bit(int index) override { indexed("CLEAR_MOTION_OUTPUT_BIT(", index); }
  void set_aux_output_bit(int index) override { indexed("SET_AUX_OUTPUT_BIT(", index); }
  void clear_aux_output_bit(int index) override { indexed("CLEAR_AUX_OUTPUT_BIT(", index); }
  void set_motion_output_value(int index, double value) override;
  void set_aux_output_value(int index, double value) override;
  void set_axis_coupling(const AxisCoupling& coupling) override;
  void process_code(const ProcessCode& code) override;

  void turn_probe_on() override { simple("TURN_PROBE_ON()"); }
  void turn_probe_off() override { simple("TURN_PROBE_OFF()"); }

  void comment(std::string_view text) override { quoted("COMMENT(\"", text); }
  void message(std::string_view text) override { quoted("MESSAGE(\"", text); }
  void print(std::string_view text) override;
  void log_open(std::string_view file) override { quoted("LOGOPEN(\"", file); }
  void log_append(std::string_view file) override { quoted("LOGAPPEND(\"", file); }
  void log_close() override { simple("LOGCLOSE()"); }
  void log(std::string_view text) override { quoted("LOG(\"", text); }

  void program_stop() override { simple("PROGRAM_STOP()"); }
  void optional_program_stop() override { simple("OPTIONAL_PROGRAM_STOP()"); }
  void pallet_shuttle() override { simple("PALLET_SHUTTLE()"); }
  void program_end() override { simple("PROGRAM_END()"); }
  void finish() override { simple("FINISH()"); }
  void on_reset() override { simple("ON_RESET()"); }

 private:
  void prefix();
  void end_line();
  void num(double v, int decimals = 4);
  void integer(long v);
  void simple(const char* call);
  void indexed(const char* open, int index);
  void quoted(const char* open, std::string_view text);
  void pose_call(const char* open, const Pose& p);

  // Output buffer: inline appends with memcpy (the printer writes a line per motion).
  class Buffer {
   public:
    void reserve(std::size_t n) {
      if (n <= cap_) return;
      auto bigger = std::make_unique<char[]>(n);
      if (len_ > 0) std::memcpy(bigger.get(), data_.get(), len_);
      data_ = std::move(bigger);
      cap_ = n;
    }
    void append(const char* s, std::size_t n) {
      if (len_ + n > cap_) reserve(2 * (len_ + n));
      std::memcpy(data_.get() + len_, s, n);
      len_ += n;
    }
    void append(std::string_view s) { append(s.data(), s.size()); }
    /// Room for `n` more characters at the end, to write there and then count with grow().
    char* room(std::size_t n) {
      if (len_ + n > cap_) reserve(2 * (len_ + n));
      return data_.get() + len_;
    }
    void grow(std::size_t n) noexcept { len_ += n; }
    void append(const char* s) { append(s, std::strlen(s)); }
    void push_back(char c) {
      if (len_ + 1 > cap_) reserve(2 * (len_ + 1));
      data_[len_++] = c;
    }
    const char* data() const noexcept { return data_.get(); }
    std::size_t size() const noexcept { return len_; }
    bool empty() const noexcept { return len_ == 0; }
    void clear() noexcept { len_ = 0; }

   private:
    std::unique_ptr<char[]> data_;
    std::size_t len_ = 0;
    std::size_t cap_ = 0;
  };

  std::FILE* out_;
  std::FILE* print_stream_;
  Buffer buf_;
  BlockOrigin origin_;
  int sequence_ = 1;
};

}  // namespace opencnc::canon
