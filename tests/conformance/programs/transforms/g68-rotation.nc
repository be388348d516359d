(Checks G68 rotation by 30 degrees about the origin on a square with an arc corner, then G69.)
(items: transforms.g68-g69)
(expected: rs274 output of twins/transforms/g68-rotation.ngc, which applies the rotation with SIN and COS)
O0101
G21 G90 G17
G68 X0 Y0 R30
G1 X20 Y0 F200
G1 Y10
G3 X10 Y20 I-10 J0
G1 X0 Y0
G69
G1 X20 Y0
M30
