(Checks the Fanuc 0 form M98 P0031002: more than four P digits are a repeat count 3 and program 1002.)
(items: fanuc.m98)
(expected: rs274 output of twins/fanuc/m98-compact-repeat.ngc, the three calls unrolled by hand)
O0004
G21 G90 G17
G0 X0 Y0
M98 P0031002
M30
O1002
G91 G1 Y-2 F100
G90
M99
