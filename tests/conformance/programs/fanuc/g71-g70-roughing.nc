(Checks Fanuc G71 two-block stock removal on the blocks N100..N200 after it, then G70 finishing.)
(items: fanuc.g71-g72 fanuc.o-numbers)
(expected: rs274 output of twins/fanuc/g71-g70-roughing.ngc: LinuxCNC's G71 passes, written out)
(opencnc-args: --machine lathe)
O0071
G21 G18 G40 G99
G50 S2000
G96 S150 M3
G0 X44 Z2
G71 U2 R0.5
G71 P100 Q200 U0.8 W0 F0.25
N100 G0 X16
G1 Z-6
X20 Z-8
Z-16
G2 X28 Z-20 R4
G1 Z-28
X36 Z-32
Z-40
N200 X44
G70 P100 Q200 F0.1
G0 X100 Z50
M30
