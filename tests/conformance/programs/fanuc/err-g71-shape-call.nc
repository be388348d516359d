(Rejects a G71 finishing shape that calls a subprogram: the cycle reads the shape's blocks, it does not run them.)
(items: fanuc.g71-g72)
(expect-error: fanuc.profile-block)
(opencnc-args: --machine lathe)
O0073
G21 G18 G99
G0 X40 Z2
G71 P10 Q20 U0.5 W0.1 D1. F0.2
N10 G0 X10
G1 Z-10
M98 P2000
N20 X40
M30
