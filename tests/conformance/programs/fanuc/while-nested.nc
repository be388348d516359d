(Checks nested WHILE loops DO 1 and DO 2 (a 3 x 2 grid of plunges) ending at END 2 and END 1.)
(items: fanuc.while-do)
(expected: rs274 output of twins/fanuc/while-nested.ngc, both loops unrolled by hand)
O0010
G21 G90 G17
#10 = 0
WHILE [#10 LT 2] DO 1
#11 = 0
WHILE [#11 LT 3] DO 2
G0 X[#11 * 10] Y[#10 * 10]
G1 Z-1 F100
G0 Z1
#11 = #11 + 1
END 2
#10 = #10 + 1
END 1
M30
