// SPDX-License-Identifier: GPL-3.0-or-later
// Stable identifiers of every problem the G-code interpreter reports (Diagnostic::code).
#pragma once

#include <cstdint>
#include <string_view>

namespace opencnc::gcode {

// X(enumerator, stable id). One id per problem a person can act on; ids never change meaning
// (tests and front ends match on them). docs/error-codes.md describes each in one line, and
// tests/conformance/error-codes.tsv maps LinuxCNC's messages onto them.
#define OPENCNC_GCODE_ERRORS(X)                                         \
  /* reading a line */                                                  \
  X(LineTooLong, "gcode.line-too-long")                                 \
  X(UnclosedComment, "gcode.unclosed-comment")                          \
  X(NestedComment, "gcode.nested-comment")                              \
  X(BadCharacter, "gcode.bad-character")                                \
  X(AxisNotAvailable, "gcode.axis-not-available")                       \
  X(LineNumberNotFirst, "gcode.line-number-not-first")                  \
  X(PercentMisplaced, "gcode.percent-misplaced")                        \
  X(BadLineNumber, "gcode.bad-line-number")                             \
  X(BadNumber, "gcode.bad-number")                                      \
  X(MissingValue, "gcode.missing-value")                                \
  X(UnknownWord, "gcode.unknown-word")                                  \
  X(RepeatedWord, "gcode.repeated-word")                                \
  /* expressions */                                                     \
  X(UnknownOperator, "gcode.unknown-operator")                          \
  X(UnclosedExpression, "gcode.unclosed-expression")                    \
  X(FunctionBracketMissing, "gcode.function-bracket-missing")           \
  X(AtanSyntax, "gcode.atan-syntax")                                    \
  X(ExistsSyntax, "gcode.exists-syntax")                                \
  X(DivideByZero, "gcode.divide-by-zero")                               \
  X(PowerDomain, "gcode.power-domain")                                  \
  X(SqrtNegative, "gcode.sqrt-negative")                                \
  X(LnNonPositive, "gcode.ln-non-positive")                             \
  X(TrigDomain, "gcode.trig-domain")                                    \
  X(ResultNotANumber, "gcode.result-not-a-number")                      \
  X(ResultInfinite, "gcode.result-infinite")                            \
  X(NotAnInteger, "gcode.not-an-integer")                               \
  /* parameters */                                                      \
  X(ParameterOutOfRange, "gcode.parameter-out-of-range")                \
  X(ParameterReadOnly, "gcode.parameter-read-only")                     \
  X(EqualSignMissing, "gcode.equal-sign-missing")                       \
  X(NameNotTerminated, "gcode.name-not-terminated")                     \
  X(NamedParameterUndefined, "gcode.named-parameter-undefined")         \
  /* G and M codes, modal groups */                                     \
  X(GCodeOutOfRange, "gcode.g-code-out-of-range")                       \
  X(UnknownGCode, "gcode.unknown-g-code")                               \
  X(MCodeOutOfRange, "gcode.m-code-out-of-range")                       \
  X(UnknownMCode, "gcode.unknown-m-code")                               \
  X(ModalGroupConflict, "gcode.modal-group-conflict")                   \
  X(TooManyMCodes, "gcode.too-many-m-codes")                            \
  X(Unsupported, "gcode.unsupported")                                   \
  /* words of a block */                                                \
  X(AxisWordsWithG80, "gcode.axis-words-with-g80")                      \
  X(AxisWordsMissing, "gcode.axis-words-missing")                       \
  X(AxisWordsConflict, "gcode.axis-words-conflict")                     \
  X(AxisWordsUnused, "gcode.axis-words-unused")                         \
  X(UnusedWord, "gcode.unused-word")                                    \
  X(PolarNotAvailable, "gcode.polar-not-available")                     \
  X(PolarWithXy, "gcode.polar-with-xy")                                 \
  X(PolarAtOrigin, "gcode.polar-at-origin")                             \
  X(PolarWithG53, "gcode.polar-with-g53")                               \
  X(PolarWithoutMotion, "gcode.polar-without-motion")                   \
  /* dwell, G10, G53 */                                                 \
  X(DwellMissing, "gcode.dwell-missing")                                \
  X(DwellWithArc, "gcode.dwell-with-arc")                               \
  X(G10LInvalid, "gcode.g10-l-invalid")                                 \
  X(G10PNotInteger, "gcode.g10-p-not-integer")                          \
  X(G10PRange, "gcode.g10-p-range")                                     \
  X(G10IjWords, "gcode.g10-ij-words")                                   \
  X(G10L20Rotation, "gcode.g10-l20-rotation")                           \
  X(G10NoOffsets, "gcode.g10-no-offsets")                               \
  X(G10Orientation, "gcode.g10-orientation")                            \
  X(G53Motion, "gcode.g53-motion")                                      \
  X(G53Incremental, "gcode.g53-incremental")                            \
  /* feeds and spindle */                                               \
  X(FeedZero, "gcode.feed-zero")                                        \
  X(FeedNegative, "gcode.feed-negative")                                \
  X(InverseTimeFeedMissing, "gcode.inverse-time-feed-missing")          \
  X(SpindleSpeedZero, "gcode.spindle-speed-zero")                       \
  X(SpeedNegative, "gcode.speed-negative")                              \
  X(SurfaceSpeedMissing, "gcode.surface-speed-missing")                 \
  X(SpindleNumber, "gcode.spindle-number")                              \
  X(M19Direction, "gcode.m19-direction")                                \
  X(M19Angle, "gcode.m19-angle")                                        \
  X(M19Timeout, "gcode.m19-timeout")                                    \
  /* arcs */                                                            \
  X(ArcCentreMissing, "gcode.arc-centre-missing")                       \
  X(ArcMixedFormat, "gcode.arc-mixed-format")                           \
  X(ArcOffsetWrongPlane, "gcode.arc-offset-wrong-plane")                \
  X(ArcCentreIncomplete, "gcode.arc-centre-incomplete")                 \
  X(ArcEndpointMissing, "gcode.arc-endpoint-missing")                   \
  X(ArcZeroRadius, "gcode.arc-zero-radius")                             \
  X(ArcEndOffCircle, "gcode.arc-end-off-circle")                        \
  X(ArcRadiusTooSmall, "gcode.arc-radius-too-small")                    \
  X(ArcRadiusFullCircle, "gcode.arc-radius-full-circle")                \
  X(ArcUvwPlane, "gcode.arc-uvw-plane")                                 \
  X(ArcTurnsNotInteger, "gcode.arc-turns-not-integer")                  \
  X(ArcTurnsRange, "gcode.arc-turns-range")                             \
  /* lathe cycles (G70-G72) and splines (G5-G5.3) */                    \
  X(LatheProfileMissing, "gcode.lathe-profile-missing")                 \
  X(LathePlane, "gcode.lathe-plane")                                    \
  X(LatheCompensation, "gcode.lathe-comp-on")                           \
  X(LatheDepth, "gcode.lathe-depth-not-positive")                       \
  X(LatheWordConflict, "gcode.lathe-profile-word-conflict")             \
  X(LatheIncrementalUW, "gcode.lathe-profile-uw-incremental")           \
  X(LatheArcCentre, "gcode.lathe-profile-arc-centre-missing")           \
  X(LatheNotMonotonic, "gcode.lathe-profile-not-monotonic")             \
  X(LatheParallel, "gcode.lathe-profile-parallel")                      \
  X(LatheCornerFinish, "gcode.lathe-corner-finish")                     \
  X(LatheLostProfile, "gcode.lathe-profile-lost")                       \
  X(LatheNoProgress, "gcode.lathe-no-progress")                         \
  X(SplinePlane, "gcode.spline-plane")                                  \
  X(SplineAxes, "gcode.spline-axes")                                    \
  X(SplineCompensation, "gcode.spline-comp-on")                         \
  X(SplineWords, "gcode.spline-words-missing")                          \
  X(NurbsPoint, "gcode.nurbs-point-xy")                                 \
  X(NurbsWeight, "gcode.nurbs-weight")                                  \
  X(NurbsNotStarted, "gcode.nurbs-not-started")                         \
  X(NurbsTooFewPoints, "gcode.nurbs-too-few-points")                    \
  X(NurbsBlockCodes, "gcode.nurbs-block-codes")                         \
  /* tools */                                                           \
  X(ToolNotFound, "gcode.tool-not-found")                               \
  X(ToolNegative, "gcode.tool-negative")                                \
  X(ToolNotPrepared, "gcode.tool-not-prepared")                         \
  X(ToolGuardCheck, "gcode.tool-guard-check")                           \
  X(HWordNegative, "gcode.h-word-negative")                             \
  X(LWordNegative, "gcode.l-word-negative")                             \
  X(M61QMissing, "gcode.m61-q-missing")                                 \
  X(G43_2HMissing, "gcode.g43-2-h-missing")                             \
  X(G43_2AxisWords, "gcode.g43-2-axis-words")                           \
  /* machine I/O and saved modal state */                               \
  X(IoOutputMissing, "gcode.io-output-missing")                         \
  X(IoAnalogOutputMissing, "gcode.io-analog-output-missing")            \
  X(IoM66BothInputs, "gcode.io-m66-both-inputs")                        \
  X(IoM66InputMissing, "gcode.io-m66-input-missing")                    \
  X(IoM66TimeoutMissing, "gcode.io-m66-timeout-missing")                \
  X(IoM66AnalogWait, "gcode.io-m66-analog-wait")                        \
  X(RestoreWithoutSave, "gcode.restore-without-save")                   \
  /* rules of cutter compensation that the core checks */               \
  X(CompCoordinateSystem, "gcode.comp-coordinate-system")               \
  X(CompActiveSystemOffset, "gcode.comp-active-system-offset")          \
  X(CompAxisOffsets, "gcode.comp-axis-offsets")                         \
  X(CompPlaneChange, "gcode.comp-plane-change")                         \
  X(CompYzPlane, "gcode.comp-yz-plane")                                 \
  X(CompToolChange, "gcode.comp-tool-change")                           \
  X(CompToolOffset, "gcode.comp-tool-offset")                           \
  X(CompG28G30, "gcode.comp-g28-g30")                                   \
  X(CompReferencePoint, "gcode.comp-reference-point")                   \
  X(CompG53, "gcode.comp-g53")                                          \
  X(CompRetractMode, "gcode.comp-retract-mode")                         \
  X(CompControlMode, "gcode.comp-control-mode")                         \
  X(CompIo, "gcode.comp-io")                                            \
  X(CompOverrides, "gcode.comp-overrides")                              \
  X(CompPositionRead, "gcode.comp-position-read")                       \
  X(CompExitArc, "gcode.comp-exit-arc")                                 \
  /* cutter radius compensation module */                               \
  X(CompWrongPlane, "gcode.comp-wrong-plane")                           \
  X(CompAlreadyOn, "gcode.comp-already-on")                             \
  X(CompDiameterMissing, "gcode.comp-diameter-missing")                 \
  X(CompToolNumber, "gcode.comp-tool-number")                           \
  X(CompEntryTooShort, "gcode.comp-entry-too-short")                    \
  X(CompArcTooSmall, "gcode.comp-arc-too-small")                        \
  X(CompGouge, "gcode.comp-gouge")                                      \
  X(CompConcentricArcs, "gcode.comp-concentric-arcs")                   \
  X(CompArcOffCircle, "gcode.comp-arc-off-circle")                      \
  X(CompInternal, "gcode.comp-internal")                                \
  /* codes of feature modules whose read-time rules the core checks */  \
  X(CycleRotaryAxis, "gcode.cycle-rotary-axis")                         \
  X(ThreadPitchMissing, "gcode.thread-pitch-missing")                   \
  X(PerTurnTooSmall, "gcode.per-turn-too-small")                        \
  X(ThreadFeedWord, "gcode.thread-feed-word")                           \
  X(ThreadG76WordMissing, "gcode.thread-g76-word-missing")              \
  /* canned cycles, threading and probing */                            \
  X(CompCannedCycle, "gcode.comp-canned-cycle")                         \
  X(CycleInverseTime, "gcode.cycle-inverse-time")                       \
  X(CycleRMissing, "gcode.cycle-r-missing")                             \
  X(CycleRBelowBottom, "gcode.cycle-r-below-bottom")                    \
  X(CycleBottomMissing, "gcode.cycle-bottom-missing")                   \
  X(CycleQMissing, "gcode.cycle-q-missing")                             \
  X(CycleQNotPositive, "gcode.cycle-q-not-positive")                    \
  X(CycleRepeatZero, "gcode.cycle-repeat-zero")                         \
  X(CycleDwellMissing, "gcode.cycle-dwell-missing")                     \
  X(CycleG87WordMissing, "gcode.cycle-g87-word-missing")                \
  X(CycleTappingPlane, "gcode.cycle-tapping-plane")                     \
  X(SpindleStopped, "gcode.spindle-stopped")                            \
  X(SpindleWrongDirection, "gcode.spindle-wrong-direction")             \
  X(CompSpindleSync, "gcode.comp-spindle-sync")                         \
  X(ThreadG76Depth, "gcode.thread-g76-depth")                           \
  X(ThreadG76Word, "gcode.thread-g76-word")                             \
  X(ThreadG76RotaryAxis, "gcode.thread-g76-rotary-axis")                \
  X(CompProbe, "gcode.comp-probe")                                      \
  X(ProbeFeedPerRevolution, "gcode.probe-feed-per-revolution")          \
  X(ProbeStartTooClose, "gcode.probe-start-too-close")                  \
  X(ProbeNoContact, "gcode.probe-no-contact")                           \
  /* program structure */                                               \
  X(ProgramEmpty, "gcode.program-empty")                                \
  X(MissingClosingPercent, "gcode.missing-closing-percent")             \
  X(MissingProgramEnd, "gcode.missing-program-end")                     \
  X(CannotOpenFile, "gcode.cannot-open-file")                           \
  X(Abort, "gcode.abort")                                               \
  /* O-words */                                                         \
  X(OwordSyntax, "gcode.oword-syntax")                                  \
  X(OwordUnknownKeyword, "gcode.oword-unknown-keyword")                 \
  X(OwordConditionMissing, "gcode.oword-condition-missing")             \
  X(OwordSubNotFound, "gcode.oword-sub-not-found")                      \
  X(OwordUnmatched, "gcode.oword-unmatched")                            \
  X(OwordMismatched, "gcode.oword-mismatched")                          \
  X(OwordUnclosed, "gcode.oword-unclosed")                              \
  X(OwordLabelDuplicate, "gcode.oword-label-duplicate")                 \
  X(OwordSubRedefined, "gcode.oword-sub-redefined")                     \
  X(OwordSubNested, "gcode.oword-sub-nested")                           \
  X(OwordNotInSub, "gcode.oword-not-in-sub")                            \
  X(OwordTooManyArgs, "gcode.oword-too-many-args")                      \
  X(OwordInMdi, "gcode.oword-in-mdi")                                   \
  X(OwordMixedStyles, "gcode.oword-mixed-styles")                       \
  /* Fanuc dialect and coordinate transforms */                         \
  X(FanucGotoTargetMissing, "fanuc.goto-target-missing")                \
  X(FanucEndWithoutDo, "fanuc.end-without-do")                          \
  X(FanucDoWithoutEnd, "fanuc.do-without-end")                          \
  X(FanucLoopStructure, "fanuc.loop-structure")                         \
  X(FanucIfSyntax, "fanuc.if-syntax")                                   \
  X(FanucProgramNotFound, "fanuc.program-not-found")                    \
  X(FanucCallProgramMissing, "fanuc.call-program-missing")              \
  X(FanucCallCountConflict, "fanuc.call-count-conflict")                \
  X(FanucStatementSyntax, "fanuc.statement-syntax")                     \
  X(FanucCycleWordMissing, "fanuc.cycle-word-missing")                  \
  X(FanucCycleWordValue, "fanuc.cycle-word-value")                      \
  X(FanucProfileBlock, "fanuc.profile-block")                           \
  X(FanucScaleWords, "fanuc.scale-words")                               \
  X(FanucRotationAngleMissing, "fanuc.rotation-angle-missing")          \
  X(FanucRotationPlane, "fanuc.rotation-plane")                         \
  X(FanucProgramEndMissing, "fanuc.program-end-missing")                \
  X(FanucReadOnlyVariable, "fanuc.read-only-variable")                  \
  X(FanucVariableUnavailable, "fanuc.variable-unavailable")             \
  X(FanucAlarm, "fanuc.alarm")                                          \
  X(FanucMirrorAxesMissing, "fanuc.mirror-axes-missing")                \
  X(FanucScaleZero, "fanuc.scale-zero")                                 \
  X(FanucRotationPlaneChange, "fanuc.rotation-plane-change")            \
  X(FanucArcNonUniformScale, "fanuc.arc-nonuniform-scale")              \
  X(FanucTransformActive, "fanuc.transform-active")                     \
  /* axis coupling (broaching codes M171-M175) */                       \
  X(CouplingWord, "coupling.word")                                      \
  X(CouplingCutterComp, "coupling.cutter-comp")                         \
  /* sinker EDM (M180, M181) */                                         \
  X(EdmCondition, "edm.condition")                                      \
  /* runaway protection */                                              \
  X(LimitCallDepth, "gcode.limit-call-depth")                           \
  X(LimitBlocks, "gcode.limit-blocks")                                  \
  X(LimitTime, "gcode.limit-time")                                      \
  X(LimitLoopIterations, "gcode.limit-loop-iterations")                 \
  X(LimitRepeatCount, "gcode.limit-repeat-count")                       \
  X(LimitSegments, "gcode.limit-segments")                              \
  X(LimitSkippedLines, "gcode.limit-skipped-lines")                     \
  X(LimitMainRepeats, "gcode.limit-main-repeats")                       \
  /* another controller's syntax in this dialect */                     \
  X(DialectUnsupported, "dialect.unsupported")                          \
  /* interface use */                                                   \
  X(NoProgram, "gcode.no-program")                                      \
  /* warnings (the program runs; opencnc check and scan report them) */ \
  X(UnitsNotProgrammed, "gcode.units-not-programmed")                   \
  X(FeedWithSpindleStopped, "gcode.feed-with-spindle-stopped")          \
  X(MainProgramRepeats, "gcode.main-program-repeats")

enum class ErrorCode : std::uint16_t {
#define OPENCNC_GCODE_ENUM(e, id) e,
  OPENCNC_GCODE_ERRORS(OPENCNC_GCODE_ENUM)
#undef OPENCNC_GCODE_ENUM
};

/// The stable id of an error code ("gcode.bad-character"). Any thread; real-time safe.
std::string_view error_id(ErrorCode code) noexcept;

/// Every error code, in declaration order (for tests and documentation checks). Any thread;
/// real-time safe.
inline constexpr ErrorCode kAllErrorCodes[] = {
#define OPENCNC_GCODE_LIST(e, id) ErrorCode::e,
    OPENCNC_GCODE_ERRORS(OPENCNC_GCODE_LIST)
#undef OPENCNC_GCODE_LIST
};

}  // namespace opencnc::gcode
