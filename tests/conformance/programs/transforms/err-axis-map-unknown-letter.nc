(Rejects a program word for an axis the letter map sends to an axis the machine does not have.)
(items: transforms.axis-exchange)
(opencnc-args: --axis-map X=U)
(expect-error: gcode.axis-not-available)
O0113
G21 G90 G17
G1 X10 F100
M30
