(Checks GOTO n jumping forward over blocks to the block numbered Nn.)
(items: fanuc.goto)
(expected: rs274 output of twins/fanuc/goto-forward.ngc, without the skipped blocks)
O0007
G21 G90 G17
G1 X10 F100
GOTO 30
N20 G1 X99
G1 Y99
N30 G1 Y10
M30
