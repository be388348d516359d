(Checks IF [..] THEN assignments (Haas / Fanuc macro B), true and false conditions.)
(items: fanuc.if-goto fanuc.macro-variables)
(expected: rs274 output of twins/fanuc/if-then.ngc, with the values worked out by hand)
O0012
G21 G90 G17
#1 = 5
#2 = 0
#3 = 0
IF [#1 GT 3] THEN #2 = 7
IF [#1 LT 3] THEN #3 = 9
G1 X#2 Y#3 F100
M30
