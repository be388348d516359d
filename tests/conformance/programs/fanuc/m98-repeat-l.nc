(Checks M98 P L: the subprogram runs L times in a row.)
(items: fanuc.m98 fanuc.m99)
(expected: rs274 output of twins/fanuc/m98-repeat-l.ngc, the three calls unrolled by hand)
O0003
G21 G90 G17
G0 X0 Y0 Z5
M98 P1001 L3
G90 G0 Z5
M30
O1001 (ONE STEP OF A STAIRCASE)
G91 G1 X5 F300
Y5
M99
