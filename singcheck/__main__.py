from singcheck.cli import main

main()
