(Checks WHILE [..] DO 1 .. END 1 with a macro-variable counter.)
(items: fanuc.while-do fanuc.macro-variables)
(expected: rs274 output of twins/fanuc/while-do.ngc, the loop unrolled by hand)
O0009
G21 G90 G17
#2 = 0
WHILE [#2 LE 3] DO 1
G1 X[#2 * 2.5] Y[10 - #2] F200
#2 = #2 + 1
END 1
G0 Z5
M30
