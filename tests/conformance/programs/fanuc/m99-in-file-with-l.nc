(Checks M98 P L calling a separate-file subprogram L times; each call ends with M99.)
(items: fanuc.m98 fanuc.m99 fanuc.separate-files)
(expected: rs274 output of twins/fanuc/m99-in-file-with-l.ngc, the two calls unrolled by hand)
O0013
G21 G90 G17
G0 X0 Y0
M98 P9001 L2
M30
