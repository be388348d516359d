(Checks G51 uniform scaling by P1.5 about X10 Y10 on lines and an arc, then G50.)
(items: transforms.g51-g50)
(expected: rs274 output of twins/transforms/g51-scaling.ngc, scaled by hand)
O0105
G21 G90 G17
G51 X10 Y10 P1.5
G0 X10 Y10
G1 X20 F100
G3 X10 Y20 R10
G1 Y10
G50
G1 X0 Y0
M30
