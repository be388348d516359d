(Rejects an arc under G68 rotation after switching to the XZ plane, where the XY rotation does not apply.)
(items: transforms.g68-g69)
(expect-error: fanuc.rotation-plane-change)
O0111
G21 G90 G17
G68 X0 Y0 R45
G18
G2 X10 Z0 I5 K0 F100
M30
