(Fanuc-dialect subprogram file for the conformance suite: #100 steps of 2 mm along X.)
O9002
#1 = 0
WHILE [#1 LT #100] DO 1
G91 G1 X2 F100
G90
#1 = #1 + 1
END 1
M99
