"""The numbers of Girard, Filliat, Meyer, Berthoz & Guillot (2005) that we reproduce, as printed there."""

# Experiment 1, Table 1: condition -> (median, min, max) survival in seconds over ten tests each, "with a
# four-hour duration limit"; and the U statistic (p < 0.01).  A's median and maximum exceed that limit
# (14,400 s): the table cannot be read as capped at 4 h.
PAPER_SURVIVAL = {"A": (14431.5, 2531, 17274), "B": (4908.0, 2518, 8831), "U": 15}
SURVIVAL_TESTS = 10
CAP_SECONDS = 4 * 3600.0
# Experiment 2.1, Table 2: W_plan -> (Ep1, Ep2) choices in fifteen tests (W_taxon 0.55); the control: ten tests
# without Ep2, all to Ep1 ("it goes directly to E_P1").
PAPER_CHOICE = {0.65: (13, 2), 0.55: (7, 8), 0.45: (2, 13)}
CHOICE_TESTS = 15
# Experiment 2.2: the time to forget (the test's duration less the most direct path's, 46 s): mean, sd and max
# seconds over fifteen tests.
PAPER_FORGET = (178.0, 78.0, 300.0)
FORGET_TESTS = 15
FORGET_DIRECT_SECONDS = 46.0
# Experiment 3.1, Table 3: Ep at the start -> (Ep1, Ep2) choices in twenty tests with F = 0.2; Fisher's exact
# test p < 0.01.  Without the dangerous area "the animat systematically chooses the closest resource (Ep1)".
PAPER_FEAR = {0.1: (13, 7), 0.5: (2, 18)}
FEAR_TESTS = 20
# Experiment 3.2, Table 4: right / left branch length ratio -> (left, right) first choices in fifteen tests.
PAPER_TMAZE = {1.0: (3, 12), 1.5: (4, 11), 2.0: (8, 7)}
TMAZE_TESTS = 15
