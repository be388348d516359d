(Checks M98 P calling subprogram O1000 written after M30 in the same file, and M99 returning.)
(items: fanuc.m98 fanuc.m99 fanuc.o-numbers)
(expected: rs274 output of twins/fanuc/m98-local.ngc, the calls unrolled by hand)
O0002
G21 G90 G17
G0 X0 Y0
M98 P1000
G0 X50 Y0
M98 P1000
G0 X0 Y0
M30
O1000 (10 MM SQUARE FROM THE CURRENT POINT)
G91 G1 X10 F200
Y10
X-10
Y-10
G90
M99
