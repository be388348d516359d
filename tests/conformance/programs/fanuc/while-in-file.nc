(Checks a WHILE loop inside a subprogram kept in its own file (lib/O9002.nc), with a common variable #100.)
(items: fanuc.while-do fanuc.separate-files fanuc.m98 fanuc.macro-variables)
(expected: rs274 output of twins/fanuc/while-in-file.ngc, the call and loop unrolled by hand)
O0011
G21 G90 G17
#100 = 3
G0 X0 Y0
M98 P9002
G0 X0 Y0
M30
