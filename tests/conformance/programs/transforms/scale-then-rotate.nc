(Checks G51 scaling by 2 and G68 rotation by 90 degrees active together, both about the origin.)
(items: transforms.g51-g50 transforms.g68-g69)
(expected: rs274 output of twins/transforms/scale-then-rotate.ngc; uniform scaling and rotation about one point commute)
O0108
G21 G90 G17
G51 X0 Y0 P2
G68 X0 Y0 R90
G1 X5 Y0 F100
G1 X5 Y3
G69
G50
G1 X0 Y0
M30
