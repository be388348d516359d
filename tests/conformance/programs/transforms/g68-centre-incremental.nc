(Checks G68 about a centre away from the origin (X10 Y5, 90 degrees) with G91 incremental moves.)
(items: transforms.g68-g69 g90-g91)
(expected: rs274 output of twins/transforms/g68-centre-incremental.ngc, rotated by hand)
O0102
G21 G90 G17
G0 X10 Y5
G68 X10 Y5 R90
G91 G1 X10 F150
Y5
X-10
G90
G69
G0 X0 Y0
M30
