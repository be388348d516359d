(Checks G51.1 X50 mirroring about the line X = 50: X coordinates reflect and arcs reverse direction.)
(items: transforms.g51.1-g50.1)
(expected: rs274 output of twins/transforms/g51-1-mirror-x.ngc, reflected by hand)
O0103
G21 G90 G17
G51.1 X50
G0 X10 Y0
G1 X30 Y0 F200
G2 X40 Y10 I0 J10
G1 Y20
G50.1 X0
G0 X0 Y0
M30
