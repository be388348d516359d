(Rejects G51.1 without an axis word naming the mirror line.)
(items: transforms.g51.1-g50.1)
(expect-error: fanuc.mirror-axes-missing)
O0112
G21 G90 G17
G51.1
G1 X10 F100
M30
