(Rejects G51 with a scale factor of zero, which would collapse the geometry.)
(items: transforms.g51-g50)
(expect-error: fanuc.scale-zero)
O0110
G21 G90 G17
G51 X0 Y0 P0
G1 X10 F100
M30
