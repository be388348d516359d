(Checks G52 local coordinate offsets in the Fanuc dialect, and G52 X0 Y0 cancelling them.)
(items: transforms.g52 g52)
(expected: rs274 output of twins/transforms/g52-local.ngc; LinuxCNC's G52 has the same meaning)
O0107
G21 G90 G17
G52 X20 Y10
G0 X0 Y0
G1 X5 F100
G52 X0 Y0
G0 X0 Y0
M30
