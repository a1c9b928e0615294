from singcheck.cli.commands import main

main()
