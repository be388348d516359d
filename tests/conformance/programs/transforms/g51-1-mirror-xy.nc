(Checks G51.1 on both X and Y (a point reflection about X0 Y0): arcs keep their direction.)
(items: transforms.g51.1-g50.1)
(expected: rs274 output of twins/transforms/g51-1-mirror-xy.ngc, reflected by hand)
O0104
G21 G90 G17
G51.1 X0 Y0
G0 X5 Y5
G1 X15 F100
G3 X15 Y15 I0 J5
G50.1 X0 Y0
G0 X0 Y0
M30
