(Checks G51 with per-axis factors I2 J0.5 (non-uniform) on straight moves only.)
(items: transforms.g51-g50)
(expected: rs274 output of twins/transforms/g51-per-axis.ngc, scaled by hand)
O0106
G21 G90 G17
G51 X0 Y0 I2 J0.5
G1 X10 Y10 F100
G1 X-5 Y20
G50
G1 X0 Y0
M30
