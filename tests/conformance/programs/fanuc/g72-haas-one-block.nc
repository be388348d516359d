(Checks Haas's one-block G72 P Q U W D F: facing in layers along Z on the blocks N10..N20 after it.)
(items: fanuc.g71-g72 fanuc.o-numbers)
(expected: rs274 output of twins/fanuc/g72-haas-one-block.ngc: LinuxCNC's G72 passes, written out)
(opencnc-args: --machine lathe)
O0072
G21 G18 G99
G96 S120 M3
G0 X44 Z2
G72 P10 Q20 U0 W0.3 D1.5 F0.2
N10 G0 Z-6
G1 X24
G3 X14 Z-1 R5
N20 G1 X0
G0 X60 Z20
M30
