// SPDX-License-Identifier: GPL-3.0-or-later
// Stable identifiers of every problem the G-code interpreter reports (Diagnostic::code).
#pragma once

#include <cstdint>
#include <string_view>

namespace opencnc::gcode {

// X(enumerator, stable id). The ids never change meaning; tests and front ends match on them.
#define OPENCNC_GCODE_ERRORS(X)                                              \
  /* reading a line */                                                       \
  X(LineTooLong, "gcode.line-too-long")                                      \
  X(UnclosedComment, "gcode.unclosed-comment")                               \
  X(NestedComment, "gcode.nested-comment")                                   \
  X(BadCharacter, "gcode.bad-character")                                     \
  X(BadNumber, "gcode.bad-number")                                           \
  X(MissingValue, "gcode.missing-value")                                     \
  X(UnknownWord, "gcode.unknown-word")                                       \
  X(UnknownOperation, "gcode.unknown-operation")                             \
  X(UnclosedExpression, "gcode.unclosed-expression")                         \
  X(BracketMissing, "gcode.bracket-missing")                                 \
  X(AtanSlashMissing, "gcode.atan-slash-missing")                            \
  X(NotANumber, "gcode.not-a-number")                                        \
  X(Infinity, "gcode.infinity")                                              \
  X(DivideByZero, "gcode.divide-by-zero")                                    \
  X(NegativeToNonIntegerPower, "gcode.negative-power")                       \
  X(AcosRange, "gcode.acos-range")                                           \
  X(AsinRange, "gcode.asin-range")                                           \
  X(LnDomain, "gcode.ln-domain")                                             \
  X(SqrtNegative, "gcode.sqrt-negative")                                     \
  X(NotAnInteger, "gcode.not-an-integer")                                    \
  X(RepeatedWord, "gcode.repeated-word")                                     \
  X(NegativeValue, "gcode.negative-value")                                   \
  X(BadLineNumber, "gcode.bad-line-number")                                  \
  /* parameters */                                                           \
  X(ParameterOutOfRange, "gcode.parameter-out-of-range")                     \
  X(ParameterReadOnly, "gcode.parameter-read-only")                          \
  X(EqualSignMissing, "gcode.equal-sign-missing")                            \
  X(NameNotTerminated, "gcode.name-not-terminated")                          \
  X(NamedParameterUndefined, "gcode.named-parameter-undefined")              \
  X(BracketedParameter, "gcode.bracketed-parameter")                         \
  /* codes and modal groups */                                               \
  X(GCodeOutOfRange, "gcode.g-code-out-of-range")                            \
  X(UnknownGCode, "gcode.unknown-g-code")                                    \
  X(TwoGCodesSameGroup, "gcode.two-g-codes-same-group")                      \
  X(MCodeOutOfRange, "gcode.m-code-out-of-range")                            \
  X(UnknownMCode, "gcode.unknown-m-code")                                    \
  X(TwoMCodesSameGroup, "gcode.two-m-codes-same-group")                      \
  X(TooManyMCodes, "gcode.too-many-m-codes")                                 \
  X(Unsupported, "gcode.unsupported")                                        \
  /* block consistency */                                                    \
  X(AxisWordsWithG80, "gcode.axis-words-with-g80")                           \
  X(AxisWordsMissing, "gcode.axis-words-missing")                            \
  X(TwoAxisGCodes, "gcode.two-axis-g-codes")                                 \
  X(AxisWordsWithoutMotion, "gcode.axis-words-without-motion")               \
  X(PolarCoordinates, "gcode.polar-coordinates")                             \
  X(UnusedWord, "gcode.unused-word")                                         \
  X(MissingWord, "gcode.missing-word")                                       \
  X(BadWordValue, "gcode.bad-word-value")                                    \
  X(G53Usage, "gcode.g53-usage")                                             \
  X(G10Usage, "gcode.g10-usage")                                             \
  /* motion */                                                               \
  X(ZeroFeedRate, "gcode.zero-feed-rate")                                    \
  X(ZeroSpindleSpeed, "gcode.zero-spindle-speed")                            \
  X(InverseTimeFeedMissing, "gcode.inverse-time-feed-missing")               \
  X(ArcFormat, "gcode.arc-format")                                           \
  X(ArcEndpointMissing, "gcode.arc-endpoint-missing")                        \
  X(ArcZeroRadius, "gcode.arc-zero-radius")                                  \
  X(ArcRadiusMismatch, "gcode.arc-radius-mismatch")                          \
  X(ArcRadiusTooSmall, "gcode.arc-radius-too-small")                         \
  X(ArcSameEndpoint, "gcode.arc-same-endpoint")                              \
  X(ArcPlane, "gcode.arc-plane")                                             \
  /* tools and machine I/O */                                                \
  X(ToolNotFound, "gcode.tool-not-found")                                    \
  X(ToolNotPrepared, "gcode.tool-not-prepared")                              \
  X(ToolOffsetUsage, "gcode.tool-offset-usage")                              \
  X(IoUsage, "gcode.io-usage")                                               \
  X(ModalContext, "gcode.modal-context")                                     \
  X(SpindleUsage, "gcode.spindle-usage")                                     \
  X(CoordinateSystem, "gcode.coordinate-system")                             \
  /* program structure and O-words */                                        \
  X(FileEndedNoPercent, "gcode.file-ended-without-percent")                  \
  X(FileEndedNoEnd, "gcode.file-ended-without-end")                          \
  X(CannotOpenFile, "gcode.cannot-open-file")                                \
  X(OWordSyntax, "gcode.o-word-syntax")                                      \
  X(SubNotFound, "gcode.sub-not-found")                                      \
  X(LabelUndefined, "gcode.label-undefined")                                 \
  X(LabelMismatch, "gcode.label-mismatch")                                   \
  X(LabelDuplicate, "gcode.label-duplicate")                                 \
  X(SubRedefined, "gcode.sub-redefined")                                     \
  X(NestedSub, "gcode.nested-sub")                                           \
  X(NotInSub, "gcode.not-in-sub")                                            \
  X(TooManyArguments, "gcode.too-many-arguments")                            \
  X(CallDepth, "gcode.call-depth")                                           \
  X(ContextRestore, "gcode.context-restore")                                 \
  X(Abort, "gcode.abort")                                                    \
  /* runaway protection */                                                   \
  X(LimitBlocks, "gcode.limit-blocks")                                       \
  X(LimitLoopIterations, "gcode.limit-loop-iterations")                      \
  X(LimitRepeatCount, "gcode.limit-repeat-count")                            \
  X(LimitSegments, "gcode.limit-segments")                                   \
  X(LimitSkippedLines, "gcode.limit-skipped-lines")                          \
  /* interface use */                                                        \
  X(NoProgram, "gcode.no-program")                                           \
  X(AwaitingSync, "gcode.awaiting-sync")                                     \
  /* warnings (the program runs; opencnc check and scan report them) */     \
  X(UnitsNotProgrammed, "gcode.units-not-programmed")                        \
  X(FeedWithSpindleStopped, "gcode.feed-with-spindle-stopped")

enum class ErrorCode : std::uint16_t {
#define OPENCNC_GCODE_ENUM(e, id) e,
  OPENCNC_GCODE_ERRORS(OPENCNC_GCODE_ENUM)
#undef OPENCNC_GCODE_ENUM
};

/// The stable id of an error code ("gcode.bad-character"). Any thread; real-time safe.
std::string_view error_id(ErrorCode code) noexcept;

}  // namespace opencnc::gcode
