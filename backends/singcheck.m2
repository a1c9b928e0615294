-- singcheck.m2: elimination requests of the singcheck command-line tool (Macaulay2).
--
-- singcheck writes a script that loads this file, defines a ring over QQ and an ideal,
-- and calls scEliminate.  Results are printed between marker lines that singcheck
-- requires exactly once each; anything else on the output is treated as a failure.

-- scEliminate(I, vs, label): print the non-zero generators of the elimination ideal
-- of I for the variables vs, one per line (toString syntax), between
-- "@@singcheck-begin <label> <n>" and "@@singcheck-end <label>".
scEliminate = (I, vs, label) -> (
    E := select(flatten entries gens eliminate(vs, I), p -> p != 0);
    print("@@singcheck-begin " | label | " " | toString(#E));
    scan(E, p -> print toString p);
    print("@@singcheck-end " | label);
    )
