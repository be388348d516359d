(Checks M98 calling O9001, kept in its own file lib/O9001.nc on the search path.)
(items: fanuc.m98 fanuc.separate-files)
(expected: rs274 output of twins/fanuc/m98-separate-file.ngc, the call unrolled by hand)
O0006
G21 G90 G17
G0 X5 Y5
M98 P9001
G0 X20 Y5
M98 P9001
M30
