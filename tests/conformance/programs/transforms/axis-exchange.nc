(Checks axis exchange: with the letter map X=Y,Y=X the program's X words drive Y and its Y words drive X.)
(items: transforms.axis-exchange)
(opencnc-args: --axis-map X=Y,Y=X)
(expected: rs274 output of twins/transforms/axis-exchange.ngc, the letters swapped by hand; arcs change direction)
O0109
G21 G90 G17
G0 X10 Y2
G1 X20 F100
G2 X30 Y12 I0 J10
M30
