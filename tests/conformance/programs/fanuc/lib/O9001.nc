(Fanuc-dialect subprogram file for the conformance suite: a 4 mm circle around the current point.)
O9001
G91 G1 X4 F150
G3 I-4 J0
G1 X-4
G90
M99
