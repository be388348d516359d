(Rejects M98 calling a program number that exists neither in the file nor on the search path.)
(items: fanuc.m98 fanuc.separate-files)
(expect-error: fanuc.program-not-found)
O0023
G21 G90 G17
M98 P4321
M30
