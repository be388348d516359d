(Checks a loop made of a macro counter, IF [..] GOTO n jumping backwards, and #1 = #1 + 1 without brackets.)
(items: fanuc.if-goto fanuc.goto fanuc.macro-variables)
(expected: rs274 output of twins/fanuc/if-goto-loop.ngc, the four passes unrolled by hand)
O0008
G21 G90 G17
#1 = 0
N10 G1 X[#1 * 5] Y[#1 * #1] F120
#1 = #1 + 1
IF [#1 LT 4] GOTO 10
G0 X0 Y0
M30
